#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "helpers.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/threedtk.hpp"

using mlmap::Error;
using mlmap::Point;
using mlmap::Pose;
using mlmap::Scan;
using mlmap::io::readThreeDtkScan;
using mlmap::io::writeThreeDtkScan;
using mlmap::test::contains;
using mlmap::test::TempDir;
using mlmap::test::writeText;

namespace {

constexpr double kPi = 3.14159265358979323846;

// 3DTK's pose matrix written out element by element from slam6D's
// EulerToMatrix4 (angles in radians, the matrix acting on 3DTK coordinates).
Eigen::Matrix3d slam6dRotation(double rx, double ry, double rz) {
  const double sx = std::sin(rx), cx = std::cos(rx);
  const double sy = std::sin(ry), cy = std::cos(ry);
  const double sz = std::sin(rz), cz = std::cos(rz);
  Eigen::Matrix3d m;
  // clang-format off
  m << cy * cz, -cy * sz, sy,
      sx * sy * cz + cx * sz, -sx * sy * sz + cx * cz, -sx * cy,
      -cx * sy * cz + sx * sz, cx * sy * sz + sx * cz, cx * cy;
  // clang-format on
  return m;
}

// 3DTK (x right, y up, z forward, cm) to mlmap (x forward, y left, z up, m).
Eigen::Vector3d fromThreeDtk(const Eigen::Vector3d& p) {
  return Eigen::Vector3d(p.z(), -p.x(), p.y()) / 100.0;
}

std::string threeDtkError(const TempDir& dir, const std::string& scan_text,
                          const std::string& pose_text) {
  writeText(dir / "scan000.pose", pose_text);
  return mlmap::test::errorReading(dir / "scan000.3d", scan_text, readThreeDtkScan);
}

// Least-squares plane through the points around `seed` (a height band first,
// then twice the points within 4 cm of the previous fit), unit normal with n.z > 0.
struct PlaneFit {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  std::size_t inliers = 0;
};

PlaneFit fitHorizontalPlane(const std::vector<Point>& points, const Eigen::Vector3d& origin,
                            double min_height, double max_height, double radius) {
  PlaneFit fit;
  auto near = [&](const Point& p) { return (p - origin).head<2>().norm() < radius; };
  std::vector<Point> selected;
  for (const Point& p : points) {
    const double height = p.z() - origin.z();
    if (near(p) && height > min_height && height < max_height) selected.push_back(p);
  }
  for (int iteration = 0; iteration < 3 && selected.size() >= 3; ++iteration) {
    fit.centroid.setZero();
    for (const Point& p : selected) fit.centroid += p;
    fit.centroid /= static_cast<double>(selected.size());
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const Point& p : selected)
      covariance += (p - fit.centroid) * (p - fit.centroid).transpose();
    fit.normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvectors().col(0);
    if (fit.normal.z() < 0) fit.normal = -fit.normal;
    fit.inliers = selected.size();
    std::vector<Point> inliers;
    for (const Point& p : points) {
      if (near(p) && std::abs(fit.normal.dot(p - fit.centroid)) < 0.04) inliers.push_back(p);
    }
    selected.swap(inliers);
  }
  return fit;
}

double tiltDegrees(const Eigen::Vector3d& normal) {
  return std::acos(std::clamp(normal.z(), -1.0, 1.0)) * 180.0 / kPi;
}

std::vector<Point> worldPoints(const Scan& scan, const Pose& pose) {
  std::vector<Point> world;
  world.reserve(scan.size());
  for (const Point& p : scan.points) world.push_back(pose * p);
  return world;
}

// Fraction of `query` points with a `reference` point closer than `radius`,
// found through a voxel hash of cell size `radius` (27 neighbouring cells).
double overlapFraction(const std::vector<Point>& reference, const std::vector<Point>& query,
                       double radius) {
  struct KeyHash {
    std::size_t operator()(const Eigen::Vector3i& key) const {
      return static_cast<std::size_t>(key.x()) * 73856093u ^
             static_cast<std::size_t>(key.y()) * 19349663u ^
             static_cast<std::size_t>(key.z()) * 83492791u;
    }
  };
  auto keyOf = [radius](const Point& p) {
    return Eigen::Vector3i((p / radius).array().floor().cast<int>());
  };
  std::unordered_map<Eigen::Vector3i, std::vector<Point>, KeyHash> grid;
  for (const Point& p : reference) grid[keyOf(p)].push_back(p);
  std::size_t hits = 0;
  for (const Point& q : query) {
    const Eigen::Vector3i key = keyOf(q);
    bool found = false;
    for (int dx = -1; dx <= 1 && !found; ++dx) {
      for (int dy = -1; dy <= 1 && !found; ++dy) {
        for (int dz = -1; dz <= 1 && !found; ++dz) {
          const auto cell = grid.find(key + Eigen::Vector3i(dx, dy, dz));
          if (cell == grid.end()) continue;
          for (const Point& p : cell->second) {
            if ((p - q).squaredNorm() < radius * radius) {
              found = true;
              break;
            }
          }
        }
      }
    }
    hits += found ? 1 : 0;
  }
  return static_cast<double>(hits) / static_cast<double>(query.size());
}

}  // namespace

TEST_CASE("threedtk: converts cm and the left-handed y-up frame to metres, z up") {
  TempDir dir;
  writeText(dir / "scan000.3d", "10 20 30\n-100 -40 250\n");
  writeText(dir / "scan000.pose", "0 0 0\n0 0 0\n");
  const Scan scan = readThreeDtkScan(dir / "scan000.3d");
  REQUIRE(scan.size() == 2);
  CHECK((scan.points[0] - Point(0.30, -0.10, 0.20)).norm() < 1e-12);  // forward, right, up
  CHECK((scan.points[1] - Point(2.50, 1.00, -0.40)).norm() < 1e-12);
  CHECK(scan.pose.isApprox(Pose::Identity()));
}

TEST_CASE("threedtk: a positive 3DTK yaw turns forward to the right") {
  TempDir dir;
  writeText(dir / "scan000.3d", "0 0 100\n");  // 1 m straight ahead
  writeText(dir / "scan000.pose", "100 0 0\n0 90 0\n");
  const Scan scan = readThreeDtkScan(dir / "scan000.3d");
  // The sensor sits 1 m to the right (-y) and looks to the right.
  CHECK((scan.pose.translation() - Eigen::Vector3d(0, -1, 0)).norm() < 1e-12);
  CHECK((scan.pose.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d(0, -1, 0)).norm() < 1e-12);
  CHECK((scan.worldPoint(0) - Point(0, -2, 0)).norm() < 1e-12);
}

TEST_CASE("threedtk: world points match slam6D's own pose matrix") {
  TempDir dir;
  const Eigen::Vector3d position_cm(-3.1, -7.5, 156.9);
  const Eigen::Vector3d angles_deg(11.0, -25.0, 40.0);
  const std::vector<Eigen::Vector3d> raw = {{10, -40, 250}, {-320, 15, 80}, {0, 200, -50}};
  writeText(dir / "scan000.3d", "10 -40 250\n-320 15 80\n0 200 -50\n");
  writeText(dir / "scan000.pose", "-3.1 -7.5 156.9\n11 -25 40\n");
  const Scan scan = readThreeDtkScan(dir / "scan000.3d");
  const Eigen::Vector3d radians = angles_deg * kPi / 180.0;
  const Eigen::Matrix3d rotation = slam6dRotation(radians.x(), radians.y(), radians.z());
  REQUIRE(scan.size() == raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    INFO("point " << i);
    const Eigen::Vector3d world_3dtk = rotation * raw[i] + position_cm;
    CHECK((scan.worldPoint(i) - fromThreeDtk(world_3dtk)).norm() < 1e-12);
  }
  CHECK(std::abs(scan.pose.linear().determinant() - 1.0) < 1e-12);
}

TEST_CASE("threedtk: skips the old '360 x 225' header on line 1 only") {
  TempDir dir;
  writeText(dir / "scan000.3d", "360 x 225\n1 2 3\n");
  writeText(dir / "scan000.pose", "0 0 0 0 0 0");
  CHECK(readThreeDtkScan(dir / "scan000.3d").size() == 1);
  const std::string message = threeDtkError(dir, "1 2 3\n360 x 225\n", "0 0 0\n0 0 0\n");
  CHECK(contains(message, "scan000.3d:2"));
}

TEST_CASE("threedtk: bad input names file and line") {
  TempDir dir;
  SUBCASE("short point line") {
    const std::string message = threeDtkError(dir, "1 2 3\n4 5\n", "0 0 0\n0 0 0\n");
    CHECK(contains(message, "scan000.3d:2"));
  }
  SUBCASE("nan point") {
    CHECK(contains(threeDtkError(dir, "1 2 nan\n", "0 0 0\n0 0 0\n"), "scan000.3d:1"));
  }
  SUBCASE("empty scan") {
    CHECK(contains(threeDtkError(dir, "", "0 0 0\n0 0 0\n"), "scan000.3d:1: no points"));
  }
  SUBCASE("pose with five numbers") {
    const std::string message = threeDtkError(dir, "1 2 3\n", "0 0 0\n0 0\n");
    CHECK(contains(message, "scan000.pose:2"));
    CHECK(contains(message, "found 5"));
  }
  SUBCASE("pose with seven numbers") {
    CHECK(contains(threeDtkError(dir, "1 2 3\n", "0 0 0\n0 0 0\n7\n"), "scan000.pose:3"));
  }
  SUBCASE("non-numeric pose") {
    CHECK(contains(threeDtkError(dir, "1 2 3\n", "0 0 0\nx 0 0\n"), "scan000.pose:2"));
  }
  SUBCASE("missing pose file") {
    writeText(dir / "scan001.3d", "1 2 3\n");
    CHECK_THROWS_WITH_AS(readThreeDtkScan(dir / "scan001.3d"),
                         doctest::Contains("scan001.pose: no such file"), Error);
  }
  SUBCASE("missing scan file") {
    CHECK_THROWS_WITH_AS(readThreeDtkScan(dir / "scan009.3d"),
                         doctest::Contains("scan009.3d: no such file"), Error);
  }
}

TEST_CASE("threedtk: write then read round-trips points and pose") {
  TempDir dir;
  Scan scan = mlmap::test::randomScan(500, 3, 30.0);
  scan.pose.linear() = (Eigen::AngleAxisd(2.5, Eigen::Vector3d(1, -2, 0.5).normalized()) *
                        Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitZ()))
                           .toRotationMatrix();
  scan.pose.translation() = Eigen::Vector3d(12.5, -3.25, 0.75);

  SUBCASE("general pose") {}
  // A yaw of ±90° in mlmap's frame is 3DTK's θy = ∓90°: the Euler gimbal lock.
  SUBCASE("yaw of exactly 90 degrees") {
    scan.pose.linear() = (Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()) *
                          Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))
                             .toRotationMatrix();
  }
  SUBCASE("yaw a hair off -90 degrees") {
    scan.pose.linear() = (Eigen::AngleAxisd(-kPi / 2 + 1e-9, Eigen::Vector3d::UnitZ()) *
                          Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitX()))
                             .toRotationMatrix();
  }
  writeThreeDtkScan(dir / "scan007.3d", scan);
  REQUIRE(std::filesystem::exists(dir / "scan007.pose"));
  const Scan back = readThreeDtkScan(dir / "scan007.3d");
  mlmap::test::checkSamePoints(back, scan, 1e-12);
  CHECK((back.pose.matrix() - scan.pose.matrix()).norm() < 1e-9);
}

TEST_CASE("threedtk: 3DTK's example scans are level, in metres, and overlap in the world") {
  const auto data = mlmap::test::sharedDataDir();
  const auto folder = data ? *data / "3dtk_dat_3scans" : std::filesystem::path();
  if (!data || !std::filesystem::is_directory(folder)) {
    MESSAGE("skipped: shared/data/3dtk_dat_3scans is not present");
    return;
  }
  std::vector<Scan> scans;
  for (const char* name : {"scan000.3d", "scan001.3d", "scan002.3d"})
    scans.push_back(readThreeDtkScan(folder / name));
  for (const Scan& scan : scans) CHECK(scan.size() == 81360);

  // Odometry: each scan further forward (+x), nearly the same height and side.
  const Eigen::Vector3d origin1 = scans[1].pose.translation();
  const Eigen::Vector3d origin2 = scans[2].pose.translation();
  CHECK(scans[0].pose.isApprox(Pose::Identity()));
  CHECK(origin1.x() == doctest::Approx(1.569).epsilon(0.01));
  CHECK(origin2.x() == doctest::Approx(3.380).epsilon(0.01));
  CHECK(std::abs(origin1.y()) < 0.1);
  CHECK(std::abs(origin1.z()) < 0.1);

  for (std::size_t i = 0; i < scans.size(); ++i) {
    CAPTURE(i);
    const Pose& pose = scans[i].pose;
    const auto world = worldPoints(scans[i], pose);
    // The floor, 0.25-0.6 m below the sensor, and the ceiling, 1.7-2.3 m above.
    const PlaneFit floor = fitHorizontalPlane(world, pose.translation(), -0.6, -0.25, 3.0);
    const PlaneFit ceiling = fitHorizontalPlane(world, pose.translation(), 1.7, 2.3, 3.0);
    MESSAGE("scan00" << i << ": floor tilt " << tiltDegrees(floor.normal) << " deg at "
                     << floor.centroid.z() - pose.translation().z() << " m below the sensor ("
                     << floor.inliers << " points), ceiling tilt " << tiltDegrees(ceiling.normal)
                     << " deg at " << ceiling.centroid.z() - pose.translation().z() << " m");
    CHECK(floor.inliers > 5000);
    CHECK(ceiling.inliers > 3000);
    // The data, not the conversion, limits this: the scanner is pitched a few
    // degrees in 3DTK's world (scan000's frame) and the floor ahead of scan000
    // slopes. An axis or sign mistake would put these planes near 90 degrees.
    CHECK(tiltDegrees(floor.normal) < 6.0);
    CHECK(tiltDegrees(ceiling.normal) < 4.0);
    CHECK(floor.centroid.z() - pose.translation().z() == doctest::Approx(-0.40).epsilon(0.1));
  }

  for (std::size_t i = 1; i < scans.size(); ++i) {
    CAPTURE(i);
    const auto previous = worldPoints(scans[i - 1], scans[i - 1].pose);
    const auto current = worldPoints(scans[i], scans[i].pose);
    const double overlap_10cm = overlapFraction(previous, current, 0.10);
    // The same clouds without their poses, and with each rotation inverted (the
    // other sign convention): both must fit clearly worse.
    const double unposed_10cm = overlapFraction(scans[i - 1].points, scans[i].points, 0.10);
    Pose previous_inverted = scans[i - 1].pose, current_inverted = scans[i].pose;
    previous_inverted.linear() = scans[i - 1].pose.linear().transpose();
    current_inverted.linear() = scans[i].pose.linear().transpose();
    const double overlap_5cm = overlapFraction(previous, current, 0.05);
    const double inverted_5cm = overlapFraction(worldPoints(scans[i - 1], previous_inverted),
                                                worldPoints(scans[i], current_inverted), 0.05);
    MESSAGE("scan00" << i << " vs scan00" << i - 1 << ": " << overlap_10cm << " within 10 cm ("
                     << unposed_10cm << " without poses), " << overlap_5cm << " within 5 cm ("
                     << inverted_5cm << " with inverted rotations)");
    CHECK(overlap_10cm > 0.75);
    CHECK(overlap_10cm > unposed_10cm + 0.1);
    CHECK(overlap_5cm > inverted_5cm + 0.1);
  }
}
