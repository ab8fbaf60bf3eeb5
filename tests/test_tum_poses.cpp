#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "helpers.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/tum_poses.hpp"

using mlmap::Error;
using mlmap::Pose;
using mlmap::io::readTumPoses;
using mlmap::io::StampedPose;
using mlmap::io::writeTumPoses;
using mlmap::test::contains;
using mlmap::test::TempDir;
using mlmap::test::writeText;

namespace {

std::string tumError(const TempDir& dir, const std::string& text) {
  return mlmap::test::errorReading(dir / "poses.txt", text, readTumPoses);
}

Pose makePose(const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& translation) {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  pose.translation() = translation;
  return pose;
}

}  // namespace

TEST_CASE("tum: reads stamps, translations and quaternions") {
  TempDir dir;
  // 90 degrees about z: qz = qw = sqrt(0.5).
  writeText(dir / "poses.txt",
            "# timestamp tx ty tz qx qy qz qw\n"
            "1305031102.175304 1 2 3 0 0 0 1\n"
            "\n"
            "1305031102.211214 -1 0.5 0 0 0 0.7071067811865476 0.7071067811865476\n");
  const auto poses = readTumPoses(dir / "poses.txt");
  REQUIRE(poses.size() == 2);
  CHECK(poses[0].stamp == 1305031102.175304);
  CHECK(poses[0].pose.translation() == Eigen::Vector3d(1, 2, 3));
  CHECK(poses[0].pose.linear().isApprox(Eigen::Matrix3d::Identity()));
  CHECK(poses[1].pose.translation() == Eigen::Vector3d(-1, 0.5, 0));
  // x axis maps to y.
  CHECK((poses[1].pose.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm() <
        1e-12);
}

TEST_CASE("tum: a non-unit quaternion is normalised") {
  TempDir dir;
  writeText(dir / "poses.txt", "0 0 0 0 0 0 2 2\n");  // 90 degrees about z, length 2*sqrt(2)
  const auto poses = readTumPoses(dir / "poses.txt");
  REQUIRE(poses.size() == 1);
  const Eigen::Matrix3d rotation = poses[0].pose.linear();
  CHECK((rotation * rotation.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-12);
  CHECK((rotation * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm() < 1e-12);
}

TEST_CASE("tum: bad input names file and line") {
  TempDir dir;
  SUBCASE("wrong field count") {
    const std::string message = tumError(dir, "0 0 0 0 0 0 0 1\n# c\n1 2 3 0 0 0 1\n");
    CHECK(contains(message, "poses.txt:3"));
    CHECK(contains(message, "found 7"));
  }
  SUBCASE("too many fields") {
    CHECK(contains(tumError(dir, "0 0 0 0 0 0 0 1 9\n"), "poses.txt:1"));
  }
  SUBCASE("zero quaternion") {
    const std::string message = tumError(dir, "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 0\n");
    CHECK(contains(message, "poses.txt:2"));
    CHECK(contains(message, "zero length"));
  }
  SUBCASE("non-numeric field") {
    CHECK(contains(tumError(dir, "0 0 zero 0 0 0 0 1\n"), "poses.txt:1"));
  }
  SUBCASE("nan") {
    CHECK(contains(tumError(dir, "\n0 0 0 0 nan 0 0 1\n"), "poses.txt:2"));
  }
  SUBCASE("huge quaternion") {
    CHECK(contains(tumError(dir, "0 0 0 0 1e300 1e300 0 1\n"), "poses.txt:1"));
  }
  SUBCASE("empty file") {
    CHECK(contains(tumError(dir, ""), "poses.txt:1: no poses"));
  }
  SUBCASE("missing file") {
    CHECK_THROWS_WITH_AS(readTumPoses(dir / "none.txt"),
                         doctest::Contains("none.txt: no such file"), Error);
  }
}

TEST_CASE("tum: write then read round-trips with full precision, qw >= 0") {
  TempDir dir;
  std::vector<StampedPose> poses;
  poses.push_back({1305031102.1753049, makePose({1, 2, 3}, 0.3, {0.1, -2.2, 3.3})});
  poses.push_back({1305031102.2112141, makePose({0, 0, 1}, 3.0, {1e-7, 123456.789, -0.5})});
  // A rotation whose quaternion, as Eigen extracts it from the matrix, has w < 0.
  poses.push_back({2.0, makePose({0.1, 0.2, -1}, 3.0, {0, 0, 0})});
  REQUIRE(Eigen::Quaterniond(poses[2].pose.linear()).w() < 0.0);
  writeTumPoses(dir / "out.txt", poses);

  const auto back = readTumPoses(dir / "out.txt");
  REQUIRE(back.size() == poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    INFO("pose " << i);
    CHECK(back[i].stamp == poses[i].stamp);
    CHECK(back[i].pose.translation() == poses[i].pose.translation());
    CHECK((back[i].pose.linear() - poses[i].pose.linear()).norm() < 1e-14);
  }

  std::ifstream in(dir / "out.txt");
  std::string line;
  int pose_lines = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    ++pose_lines;
    const double qw = std::stod(line.substr(line.rfind(' ') + 1));
    CHECK(qw >= 0.0);
  }
  CHECK(pose_lines == 3);
}

TEST_CASE("tum: writer refuses non-finite poses and leaves no file") {
  TempDir dir;
  std::vector<StampedPose> poses(1);
  poses[0].stamp = std::nan("");
  CHECK_THROWS_WITH_AS(writeTumPoses(dir / "out.txt", poses), doctest::Contains("pose 0"), Error);
  CHECK_FALSE(std::filesystem::exists(dir / "out.txt"));
}
