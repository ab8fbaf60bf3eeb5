#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "helpers.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/scan_graph.hpp"

using mlmap::Error;
using mlmap::Point;
using mlmap::Pose;
using mlmap::Scan;
using mlmap::io::readScanGraph;
using mlmap::io::writeScanGraph;
using mlmap::test::contains;
using mlmap::test::readText;
using mlmap::test::TempDir;
using mlmap::test::writeText;

namespace {

std::vector<Scan> twoScans() {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-10.0, 10.0);
  std::vector<Scan> scans(2);
  for (int i = 0; i < 300; ++i)
    scans[0].points.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
  for (int i = 0; i < 200; ++i)
    scans[1].points.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
  scans[0].pose.translation() = Eigen::Vector3d(0.5, -1.25, 0.1);
  scans[1].pose.linear() =
      Eigen::AngleAxisd(0.8, Eigen::Vector3d(0.2, -0.3, 1).normalized()).toRotationMatrix();
  scans[1].pose.translation() = Eigen::Vector3d(2.0, 1.5, -0.25);
  return scans;
}

std::string graphError(const TempDir& dir, const std::string& bytes) {
  return mlmap::test::errorReading(dir / "bad.graph", bytes, readScanGraph);
}

void putU32(std::string& bytes, std::size_t offset, std::uint32_t value) {
  std::memcpy(bytes.data() + offset, &value, sizeof(value));  // little-endian host, as octomap
}

}  // namespace

TEST_CASE("scan_graph: write then read round-trips points and poses (float precision)") {
  TempDir dir;
  const auto scans = twoScans();
  writeScanGraph(dir / "two.graph", scans);
  const auto back = readScanGraph(dir / "two.graph");
  REQUIRE(back.size() == 2);
  for (std::size_t s = 0; s < scans.size(); ++s) {
    CAPTURE(s);
    REQUIRE(back[s].size() == scans[s].size());
    double worst = 0.0;
    for (std::size_t i = 0; i < scans[s].size(); ++i) {
      worst = std::max(worst, (back[s].points[i] - scans[s].points[i]).cwiseAbs().maxCoeff());
    }
    CHECK(worst < 1e-5);
    CHECK((back[s].pose.translation() - scans[s].pose.translation()).norm() < 1e-6);
    CHECK((back[s].pose.linear() - scans[s].pose.linear()).norm() < 1e-6);
  }
  // Layout: counts, 28 bytes per point, 64 per pose, a node id, one edge of 80 bytes.
  const std::size_t expected_bytes = 4 + (4 + 300 * 28 + 64 + 4) + (4 + 200 * 28 + 64 + 4) + 4 + 80;
  CHECK(std::filesystem::file_size(dir / "two.graph") == expected_bytes);
}

TEST_CASE("scan_graph: reads Debian's spherical_scan.graph") {
  const auto path = mlmap::test::octomapExampleDir() / "spherical_scan.graph";
  if (!std::filesystem::exists(path)) {
    MESSAGE("skipped: " << path.string() << " is not installed (liboctomap-dev examples)");
    return;
  }
  const auto scans = readScanGraph(path);
  REQUIRE(scans.size() == 1);
  CHECK(scans[0].size() == 10201);  // 101 x 101 beams of a spherical sweep
  for (const Point& p : scans[0].points) REQUIRE(p.allFinite());
  CHECK(std::abs(scans[0].pose.linear().determinant() - 1.0) < 1e-6);
}

TEST_CASE("scan_graph: reads octomap's plain-ASCII log") {
  TempDir dir;
  writeText(dir / "log.graph",
            "# a log\n"
            "NODE 1 2 0.5 0 0 1.5707963267948966\n"
            "1 0 0\n"
            "0 1 0\n"
            "NODE 0 0 0 0 0 0\n"
            "3 3 3\n");
  const auto scans = readScanGraph(dir / "log.graph");
  REQUIRE(scans.size() == 2);
  REQUIRE(scans[0].size() == 2);
  CHECK(scans[1].size() == 1);
  // Yaw of 90 degrees: (1, 0, 0) lands 1 m to the left of (1, 2, 0.5).
  CHECK((scans[0].worldPoint(0) - Point(1, 3, 0.5)).norm() < 1e-6);
  CHECK(scans[1].pose.isApprox(Pose::Identity()));
}

TEST_CASE("scan_graph: hostile binary files are rejected before allocating") {
  TempDir dir;
  writeScanGraph(dir / "good.graph", twoScans());
  const std::string good = readText(dir / "good.graph");

  SUBCASE("giant node count") {
    std::string bytes = good;
    putU32(bytes, 0, 0xFFFFFFFFu);
    const std::string message = graphError(dir, bytes);
    CHECK(contains(message, "bad.graph: byte 0"));
    CHECK(contains(message, "4294967295 scans"));
  }
  SUBCASE("giant point count") {
    std::string bytes = good;
    putU32(bytes, 4, 0xFFFFFFF0u);
    const std::string message = graphError(dir, bytes);
    CHECK(contains(message, "bad.graph: byte 4"));
    CHECK(contains(message, "points"));
  }
  SUBCASE("truncated") {
    CHECK(contains(graphError(dir, good.substr(0, good.size() - 100)), "bad.graph: byte"));
  }
  SUBCASE("trailing garbage") {
    CHECK(contains(graphError(dir, good + "xyz"), "bad.graph: byte"));
  }
  SUBCASE("zero scans") {
    CHECK(contains(graphError(dir, std::string(8, '\0')),
                   "bad.graph: byte 0: scan graph holds no scans"));
  }
  SUBCASE("too short") {
    CHECK(contains(graphError(dir, "ab"), "bad.graph: byte 0"));
  }
  SUBCASE("zero quaternion") {
    std::string bytes = good;
    // First pose: after the node count, point count and 300 points; quaternion after
    // the 28-byte translation and its 4-byte length.
    const std::size_t quaternion = 4 + 4 + 300 * 28 + 28 + 4;
    std::memset(bytes.data() + quaternion, 0, 32);
    const std::string message = graphError(dir, bytes);
    CHECK(contains(message, "bad.graph: byte " + std::to_string(4 + 4 + 300 * 28)));
  }
  SUBCASE("nan point") {
    std::string bytes = good;
    const double nan = std::nan("");
    std::memcpy(bytes.data() + 4 + 4 + 5 * 28 + 4, &nan, sizeof(nan));
    const std::string message = graphError(dir, bytes);
    CHECK(contains(message, "byte " + std::to_string(4 + 4 + 5 * 28)));
    CHECK(contains(message, "point 5"));
  }
}

TEST_CASE("scan_graph: bad ASCII logs name file and line") {
  TempDir dir;
  SUBCASE("point before NODE") {
    CHECK(contains(graphError(dir, "# c\n1 2 3\n"), "bad.graph:2: point before the first NODE"));
  }
  SUBCASE("NODE without a pose") {
    CHECK(contains(graphError(dir, "# c\nNODE\n"), "bad.graph:2"));
  }
  SUBCASE("non-numeric point") {
    CHECK(contains(graphError(dir, "NODE 0 0 0 0 0 0\n1 2 x\n"), "bad.graph:2"));
  }
  SUBCASE("short point") {
    CHECK(contains(graphError(dir, "NODE 0 0 0 0 0 0\n1 2 3\n1 2\n"), "bad.graph:3"));
  }
  SUBCASE("comments only") {
    CHECK(contains(graphError(dir, "# nothing\n"), "bad.graph:1: no NODE"));
  }
}

TEST_CASE("scan_graph: missing file, and failed writes leave nothing") {
  TempDir dir;
  CHECK_THROWS_WITH_AS(readScanGraph(dir / "none.graph"),
                       doctest::Contains("none.graph: no such file"), Error);
  auto scans = twoScans();
  scans[1].points[3].x() = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH_AS(writeScanGraph(dir / "out.graph", scans),
                       doctest::Contains("scan 1: point 3"), Error);
  CHECK_THROWS_AS(writeScanGraph(dir / "out.graph", {}), Error);
  CHECK(std::filesystem::is_empty(dir.path()));
}
