// io/scan_input.hpp: scans paired with their poses, limited to the ranges a scanner
// measures, and the checks made before any scan is read.
#include <doctest/doctest.h>

#include <Eigen/Geometry>

#include "helpers.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/pcd.hpp"
#include "mlmap/io/scan_input.hpp"
#include "mlmap/io/tum_poses.hpp"
#include "mlmap/io/xyz.hpp"

using namespace mlmap;
namespace fs = std::filesystem;

namespace {

// A scan as 3DTK's look: a wall 3 m ahead, readings off the scanner's own housing at
// 0.15 m and no-return readings at the sensor's maximum, 32.76 m.
Scan scanWithJunk() {
  Scan scan;
  for (int k = 0; k < 50; ++k) scan.points.emplace_back(3.0, -1.0 + 0.04 * k, 0.5);
  for (int k = 0; k < 7; ++k) scan.points.emplace_back(0.0, 0.15, -0.01);
  for (int k = 0; k < 9; ++k) scan.points.emplace_back(32.76 * std::cos(0.1 * k), 32.76 * std::sin(0.1 * k), 0.0);
  scan.labels.assign(scan.size(), 0);
  for (std::size_t k = 0; k < scan.size(); ++k) scan.labels[k] = static_cast<std::int32_t>(k);
  return scan;
}

Pose poseAt(double x, double yaw_deg) {
  Pose pose = Pose::Identity();
  pose.translate(Eigen::Vector3d(x, 0.0, 0.0));
  pose.rotate(Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()));
  return pose;
}

}  // namespace

TEST_CASE("Scan input: the default range limits drop a scanner's own and its no-return readings") {
  Scan scan = scanWithJunk();
  const std::size_t dropped = io::applyRangeLimits(scan, io::RangeLimits{});
  CHECK(dropped == 16);
  REQUIRE(scan.size() == 50);
  CHECK(scan.labels.size() == 50);
  CHECK(scan.labels.back() == 49);  // labels stay with their points
  for (const Point& point : scan.points) CHECK(point.x() == doctest::Approx(3.0));
  // Limits of the caller's own.
  Scan wide = scanWithJunk();
  CHECK(io::applyRangeLimits(wide, io::RangeLimits{.min = 0.0, .max = 40.0}) == 0);
}

TEST_CASE("Scan input: scans in order with pose i of the pose file, limited in range, counted") {
  test::TempDir dir;
  const Scan scan = scanWithJunk();
  io::writeXyz(dir / "a.xyz", scan);
  io::writeXyz(dir / "b.xyz", scan);
  io::writeTumPoses(dir / "poses.txt", {{0.0, poseAt(1.0, 0.0)}, {1.0, poseAt(2.0, 90.0)}});
  io::ScanInput input{.files = {dir / "a.xyz", dir / "b.xyz"}, .poses = dir / "poses.txt"};
  input.world = Pose(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));
  const io::ScanSequence sequence(input);
  std::vector<Pose> seen;
  std::vector<std::size_t> files_done;
  const io::ScanInputCounts counts = sequence.forEach(
      [&](Scan& read, std::size_t index, std::size_t file) {
        CHECK(index == file);
        CHECK(read.size() == 50);
        seen.push_back(read.pose);
      },
      [&](std::size_t file) { files_done.push_back(file); });
  CHECK(counts.scans == 2);
  CHECK(counts.points == 100);
  CHECK(counts.too_near == 14);
  CHECK(counts.too_far == 18);
  CHECK(files_done == std::vector<std::size_t>{0, 1});
  REQUIRE(seen.size() == 2);
  // The world turn comes after the pose.
  CHECK(seen[1].isApprox(input.world * poseAt(2.0, 90.0), 1e-9));
  // Corrected poses replace them and are not turned again.
  const io::ScanSequence corrected = sequence.withPoses({{0.0, poseAt(5.0, 0.0)}, {1.0, poseAt(6.0, 0.0)}});
  seen.clear();
  corrected.forEach([&](Scan& read, std::size_t, std::size_t) { seen.push_back(read.pose); });
  REQUIRE(seen.size() == 2);
  CHECK(seen[1].isApprox(poseAt(6.0, 0.0), 1e-9));
}

TEST_CASE("Scan input: a scan without a pose needs a pose file or identity, checked before reading") {
  test::TempDir dir;
  io::writeXyz(dir / "a.xyz", scanWithJunk());
  // A file whose body is broken: the pose rule fails first, so nothing was read.
  test::writeText(dir / "broken.xyz", "0 0 nan\n");
  const std::string message = test::errorOf([&] { io::ScanSequence(io::ScanInput{.files = {dir / "broken.xyz"}}); });
  CHECK(test::contains(message, "broken.xyz: the scan carries no pose"));
  CHECK(test::contains(message, "--identity"));
  // With identity the scan sits at the origin.
  const io::ScanSequence identity(io::ScanInput{.files = {dir / "a.xyz"}, .identity = true});
  identity.forEach([](Scan& read, std::size_t, std::size_t) {
    CHECK(read.pose.isApprox(Pose::Identity()));
  });
  // A PCD carries its pose in VIEWPOINT; one without that line does not.
  Scan posed = scanWithJunk();
  posed.pose = poseAt(1.0, 30.0);
  io::writePcd(dir / "posed.pcd", posed, io::PcdEncoding::Ascii);
  io::ScanSequence(io::ScanInput{.files = {dir / "posed.pcd"}}).forEach([&](Scan& read, std::size_t, std::size_t) {
    CHECK(read.pose.isApprox(posed.pose, 1e-6));
  });
  std::string text = test::readText(dir / "posed.pcd");
  const std::size_t viewpoint = text.find("VIEWPOINT");
  REQUIRE(viewpoint != std::string::npos);
  text.erase(viewpoint, text.find('\n', viewpoint) - viewpoint + 1);
  test::writeText(dir / "bare.pcd", text);
  CHECK(test::contains(test::errorOf([&] { io::ScanSequence(io::ScanInput{.files = {dir / "bare.pcd"}}); }),
                       "bare.pcd: the scan carries no pose"));
}

TEST_CASE("Scan input: pose counts, formats and missing files fail before any scan is read") {
  test::TempDir dir;
  io::writeXyz(dir / "a.xyz", scanWithJunk());
  io::writeTumPoses(dir / "three.txt", {{0.0, poseAt(0, 0)}, {1.0, poseAt(1, 0)}, {2.0, poseAt(2, 0)}});
  CHECK(test::contains(
      test::errorOf([&] { io::ScanSequence(io::ScanInput{.files = {dir / "a.xyz"}, .poses = dir / "three.txt"}); }),
      "three.txt: 3 poses for 1 scans"));
  CHECK(test::contains(test::errorOf([&] { io::ScanSequence(io::ScanInput{.files = {dir / "a.las"}}); }),
                       "unknown scan format"));
  CHECK(test::contains(
      test::errorOf([&] { io::ScanSequence(io::ScanInput{.files = {dir / "missing.xyz"}, .identity = true}); }),
      "missing.xyz: no such file"));
  fs::create_directory(dir / "folder.xyz");
  CHECK(test::contains(
      test::errorOf([&] { io::ScanSequence(io::ScanInput{.files = {dir / "folder.xyz"}, .identity = true}); }),
      "folder.xyz: is a directory"));
  CHECK(test::contains(test::errorOf([&] {
                         io::ScanSequence(io::ScanInput{.files = {dir / "a.xyz"},
                                                        .identity = true,
                                                        .range = {.min = 2.0, .max = 1.0}});
                       }),
                       "range limits"));
}

TEST_CASE("Scan input: a scan with readings but none within the range limits is an error naming it") {
  Scan far;
  for (int k = 0; k < 20; ++k) far.points.emplace_back(45.0 + 0.1 * k, 40.0, 1.0);
  const std::string message = test::errorOf([&] { io::requireReadingsInRange(far, io::RangeLimits{}, "cloud.xyz", 0); });
  CHECK(test::contains(message, "cloud.xyz (scan 1): none of its 20 readings lies within 0.4-30 m"));
  CHECK(test::contains(message, "60.22-61.65 m"));
  CHECK(test::contains(message, "--max-range 63"));
  // One reading within them is enough (a scan of junk and one wall is the reader's to map).
  far.points.emplace_back(3.0, 0.0, 0.0);
  CHECK_NOTHROW(io::requireReadingsInRange(far, io::RangeLimits{}, "cloud.xyz", 0));
  // Hostile values: four digits, not a hundred.
  Scan huge;
  huge.points.emplace_back(1e100, 0.0, 0.0);
  const std::string huge_message = test::errorOf([&] { io::requireReadingsInRange(huge, io::RangeLimits{}, "huge.xyz", 0); });
  CHECK(test::contains(huge_message, "they lie 1e+100-1e+100 m"));
  CHECK(huge_message.size() < 250);
  // Nothing finite, or nothing at all: nothing to say here.
  Scan empty;
  CHECK_NOTHROW(io::requireReadingsInRange(empty, io::RangeLimits{}, "empty.xyz", 0));
  Scan unknown;
  unknown.points.emplace_back(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0);
  CHECK_NOTHROW(io::requireReadingsInRange(unknown, io::RangeLimits{}, "nan.xyz", 0));
}

// Failed before (no --units): a room scanned in millimetres lies 1,000 times too far, every
// reading beyond 30 m, and the message only offered a wider range, which maps a room of
// kilometres. Now the message names --units mm, and the scale turns file and pose file to metres.
TEST_CASE("Scan input: coordinates in millimetres, read with a scale, and named in the range error") {
  test::TempDir dir;
  Scan room = scanWithJunk();
  for (Point& point : room.points) point *= 1000.0;
  io::writeXyz(dir / "mm.xyz", room);
  io::writeTumPoses(dir / "poses.txt", {{0.0, poseAt(2000.0, 90.0)}});
  const std::string message = test::errorOf([&] { io::requireReadingsInRange(room, io::RangeLimits{}, "mm.xyz", 0); });
  CHECK(test::contains(message, "if its coordinates are millimetres, --units mm"));
  io::ScanInput input{.files = {dir / "mm.xyz"}, .poses = dir / "poses.txt"};
  input.scale = 0.001;
  const io::ScanSequence sequence(input);
  std::vector<Scan> read;
  const io::ScanInputCounts counts = sequence.forEach([&](Scan& scan, std::size_t, std::size_t) { read.push_back(scan); });
  CHECK(counts.points == 50);  // the wall, as in metres; the housing and the no-returns dropped
  REQUIRE(read.size() == 1);
  CHECK(read[0].points[0].isApprox(Point(3.0, -1.0, 0.5), 1e-9));
  CHECK(read[0].pose.isApprox(poseAt(2.0, 90.0), 1e-9));
}
