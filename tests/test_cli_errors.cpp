// The CLI never gives silent garbage: every error exits 1 with one line in one style
// ("mlmap: ..."), found before the long work; scans without a pose need --identity.
#include <doctest/doctest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>

#include "box_room_rays.hpp"
#include "cli_runner.hpp"
#include "helpers.hpp"
#include "mlmap/io/xyz.hpp"

using mlmap::test::runCli;
namespace fs = std::filesystem;

namespace {

// A 6 × 4 × 2.5 m room scanned from (0, 0, 0): floor 1 m below, by rays spread over the
// sphere; plus a scanner's junk: readings off its housing (0.15 m) and no-return
// readings at 32.76 m, as 3DTK's scans hold.
mlmap::Scan roomScan(bool with_junk, const Eigen::Vector3d& low = {-2.0, -3.0, -1.0},
                     const Eigen::Vector3d& high = {4.0, 1.0, 1.5}) {
  mlmap::Scan scan;
  const auto rays = mlmap::test::boxRoomRays(30000, low, high);
  for (std::size_t k = 0; k < rays.size(); ++k) {
    const Eigen::Vector3d& direction = rays[k].direction;
    scan.points.push_back(rays[k].range * direction);
    if (with_junk && k % 20 == 0) scan.points.push_back(0.15 * direction);
    if (with_junk && k % 20 == 10) scan.points.push_back(32.76 * direction);
  }
  return scan;
}

std::size_t lineCount(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

// One line, "mlmap: " first, exit code 1, holding `part`.
void checkOneLineError(const mlmap::test::CommandResult& result, const std::string& part) {
  INFO(result.output);
  CHECK(result.exit_code == 1);
  CHECK(lineCount(result.output) == 1);
  CHECK(result.output.rfind("mlmap: ", 0) == 0);
  CHECK(mlmap::test::contains(result.output, part));
  CHECK(result.output.size() < 300);  // no 300 digits of DBL_MAX
}

struct RoomFiles {
  mlmap::test::TempDir dir;
  std::string scan = (dir / "room.xyz").string();
  std::string map = (dir / "room.mlmap").string();
  RoomFiles() { mlmap::io::writeXyz(scan, roomScan(true)); }
};

nlohmann::json infoOf(const std::string& map) {
  const auto result = runCli("info --json " + map);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  return nlohmann::json::parse(result.output);
}

}  // namespace

TEST_CASE("CLI errors: a scan that carries no pose needs --poses or --identity") {
  RoomFiles room;
  checkOneLineError(runCli("--quiet build -o " + room.map + " " + room.scan), "room.xyz: the scan carries no pose");
  CHECK_FALSE(fs::exists(room.map));
  checkOneLineError(runCli("--quiet label " + room.map + " -o " + (room.dir / "l.xyz").string() + " " + room.scan),
                    "carries no pose");
  const auto result = runCli("--quiet build --identity -o " + room.map + " " + room.scan);
  CHECK_MESSAGE(result.exit_code == 0, result.output);
}

TEST_CASE("CLI errors: parse errors, missing files and directories exit 1 with one line") {
  RoomFiles room;
  checkOneLineError(runCli("frobnicate"), "frobnicate");
  checkOneLineError(runCli("build --identity --frobnicate -o " + room.map + " " + room.scan), "--frobnicate");
  checkOneLineError(runCli(""), "subcommand");
  checkOneLineError(runCli("build --identity -o " + room.map + " " + (room.dir / "none.xyz").string()),
                    "none.xyz: no such file");
  fs::create_directory(room.dir / "folder.xyz");
  checkOneLineError(runCli("build --identity -o " + room.map + " " + (room.dir / "folder.xyz").string()),
                    "folder.xyz: is a directory");
  checkOneLineError(runCli("build --identity -o " + room.map + " " + (room.dir / "scan.las").string()),
                    "unknown scan format");
  checkOneLineError(runCli("info " + (room.dir / "none.mlmap").string()), "none.mlmap");
}

TEST_CASE("CLI errors: a device or a pipe named as an input file is refused at once, not read forever") {
  // Before: a .pcd linked to /dev/zero, `simulate /dev/zero` and `replay /dev/zero` read
  // until killed (simulate's memory grew 130 MB a second), a pipe as --poses waited for a
  // writer, and `export --dashboard-page /dev/zero` wrote an empty page without a word.
  RoomFiles room;
  REQUIRE(runCli("-q build --identity --no-octree -o " + room.map + " " + room.scan).exit_code == 0);
  const fs::path zero_pcd = room.dir / "zero.pcd";
  fs::create_symlink("/dev/zero", zero_pcd);
  const fs::path pipe = room.dir / "pipe";
  REQUIRE(::mkfifo(pipe.c_str(), 0600) == 0);
  const fs::path pipe_xyz = room.dir / "pipe.xyz";
  fs::create_symlink(pipe, pipe_xyz);
  const std::string out = (room.dir / "out").string();
  // Each under a deadline: a reader that never returns fails (124) instead of hanging.
  constexpr int kSeconds = 20;
  checkOneLineError(runCli("-q build --identity -o " + out + ".mlmap " + zero_pcd.string(), kSeconds),
                    "zero.pcd: not a regular file");
  checkOneLineError(runCli("-q build --identity -o " + out + ".mlmap " + pipe_xyz.string(), kSeconds),
                    "pipe.xyz: not a regular file");
  checkOneLineError(runCli("-q build --poses " + pipe.string() + " -o " + out + ".mlmap " + room.scan, kSeconds),
                    "pipe: not a regular file");
  checkOneLineError(
      runCli("-q build --identity --mount " + pipe.string() + " -o " + out + ".mlmap " + room.scan, kSeconds),
      "pipe: not a regular file");
  checkOneLineError(
      runCli("-q merge " + room.map + " " + room.map + " --transform " + pipe.string() + " -o " + out + ".mlmap",
             kSeconds),
      "pipe: not a regular file");
  checkOneLineError(runCli("-q simulate /dev/zero -o " + out, kSeconds), "/dev/zero: not a regular file");
  checkOneLineError(runCli("-q replay /dev/zero -o " + out, kSeconds), "/dev/zero: not a regular file");
  checkOneLineError(
      runCli("-q export " + room.map + " --dashboard " + out + " --dashboard-page /dev/zero", kSeconds),
      "/dev/zero: not a regular file");
  CHECK_FALSE(fs::exists(out));
  CHECK_FALSE(fs::exists(out + ".mlmap"));
}

TEST_CASE("CLI errors: numbers parse with a plain message and the paper's parameters are range-checked") {
  RoomFiles room;
  checkOneLineError(runCli("build --identity --cell-size abc -o " + room.map + " " + room.scan),
                    "--cell-size: 'abc' is not a number");
  checkOneLineError(runCli("build --identity --cell-size -0.1 -o " + room.map + " " + room.scan),
                    "--cell-size: -0.1 is not in (0, ");
  checkOneLineError(runCli("build --identity --max-range 1 --min-range 2 -o " + room.map + " " + room.scan),
                    "range limits");
  REQUIRE(runCli("--quiet build --identity -o " + room.map + " " + room.scan).exit_code == 0);
  checkOneLineError(runCli("planes " + room.map + " --probability 2"), "--probability: 2 is not in (0, 1]");
  checkOneLineError(runCli("planes " + room.map + " --kappa 500"), "--kappa: 500 is not in (0, 90]");
  checkOneLineError(runCli("planes " + room.map + " --min-area -3"), "--min-area: -3 is not in [0, ");
  checkOneLineError(runCli("planes " + room.map + " --radius 1.5"), "--radius: '1.5' is not a whole number");
  checkOneLineError(runCli("register -o " + (room.dir / "poses.tum").string() + " --scan-noise 0 " + room.scan),
                    "--scan-noise: 0 is not in (0, ");
  checkOneLineError(runCli("build --identity --scan-noise 0.01 -o " + room.map + " " + room.scan),
                    "--scan-noise requires --register");
}

TEST_CASE("CLI errors: pose counts and the output are checked before the long work") {
  RoomFiles room;
  mlmap::test::writeText(room.dir / "three.txt", "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n");
  // The second scan is broken: the pose count fails first, so no scan was read.
  mlmap::test::writeText(room.dir / "broken.xyz", "0 0 nan\n");
  checkOneLineError(runCli("--quiet build -o " + room.map + " --poses " + (room.dir / "three.txt").string() + " " +
                           room.scan + " " + (room.dir / "broken.xyz").string()),
                    "three.txt: 3 poses for 2 scans");
  checkOneLineError(runCli("--quiet build --identity -o " + (room.dir / "no" / "such" / "m.mlmap").string() + " " +
                           room.dir.path().string() + "/broken.xyz"),
                    "m.mlmap: no directory");
  checkOneLineError(runCli("--quiet build --identity -o " + room.dir.path().string() + " " + room.scan),
                    "is a directory");
}

TEST_CASE("CLI errors: label on a map without planes is refused, planes counts one kind of block") {
  RoomFiles room;
  REQUIRE(runCli("--quiet build --identity --cell-size 0.1 -o " + room.map + " " + room.scan).exit_code == 0);
  const std::string labels = (room.dir / "labels.xyz").string();
  checkOneLineError(runCli("--quiet label --identity " + room.map + " -o " + labels + " " + room.scan),
                    "has no planes");
  CHECK_FALSE(fs::exists(labels));
  const std::string labelled = (room.dir / "labelled.mlmap").string();
  const auto planes = runCli("--quiet planes " + room.map + " -o " + labelled);
  REQUIRE_MESSAGE(planes.exit_code == 0, planes.output);
  // "N blocks, M of them labelled": N is the map's block count, as `mlmap info` says.
  const std::size_t blocks = infoOf(room.map)["blocks"]["total"].get<std::size_t>();
  CHECK_MESSAGE(mlmap::test::contains(planes.output, room.map + ": " + std::to_string(blocks) + " blocks, "),
                planes.output);
  CHECK(mlmap::test::contains(planes.output, " of them labelled"));
  const auto label = runCli("--quiet label --identity " + labelled + " -o " + labels + " " + room.scan);
  CHECK_MESSAGE(label.exit_code == 0, label.output);
  // Every input point, in order, the junk ones with no plane.
  const mlmap::Scan written = mlmap::io::readXyz(labels);
  const mlmap::Scan input = mlmap::io::readXyz(room.scan);
  REQUIRE(written.size() == input.size());
  for (std::size_t k = 0; k < input.size(); ++k) {
    const double range = input.points[k].norm();
    if (range < 0.4 || range > 30.0) CHECK(written.labels[k] == -1);
  }
}

TEST_CASE("CLI: the range limits keep a scanner's junk readings out of the map") {
  RoomFiles room;
  REQUIRE(runCli("--quiet build --identity -o " + room.map + " " + room.scan).exit_code == 0);
  auto bounds = infoOf(room.map)["bounds"];
  // The room, 6 × 4 × 2.5 m, not the no-return readings' 65 m.
  CHECK(bounds["max"][0].get<double>() - bounds["min"][0].get<double>() == doctest::Approx(6.0).epsilon(0.05));
  CHECK(bounds["max"][2].get<double>() - bounds["min"][2].get<double>() == doctest::Approx(2.5).epsilon(0.1));
  const auto wide = runCli("build --identity --min-range 0 --max-range 40 -o " + room.map + " " + room.scan);
  REQUIRE_MESSAGE(wide.exit_code == 0, wide.output);
  bounds = infoOf(room.map)["bounds"];
  CHECK(bounds["max"][0].get<double>() - bounds["min"][0].get<double>() > 60.0);
  // Without --quiet, build says how many it dropped.
  const auto counted = runCli("build --identity -o " + room.map + " " + room.scan);
  CHECK(mlmap::test::contains(counted.output, "dropped 1500 readings nearer than 0.4 m and 1500 beyond 30 m"));
}

TEST_CASE("CLI: a cloud registered far from its frame's origin is refused by the range limits, not mapped empty") {
  mlmap::test::TempDir dir;
  // The room as one registered cloud 40 m out along x and y: read without a pose it is
  // "seen" from the origin, 40-50 m away, beyond the default 30 m. The map was empty
  // and the build said only how many readings it dropped (exit 0).
  mlmap::Scan cloud = roomScan(false);
  for (mlmap::Point& point : cloud.points) point += Eigen::Vector3d(40.0, 40.0, 0.0);
  const std::string scan = (dir / "far.xyz").string();
  const std::string map = (dir / "far.mlmap").string();
  mlmap::io::writeXyz(scan, cloud);
  checkOneLineError(runCli("--quiet build --identity -o " + map + " " + scan),
                    "far.xyz (scan 1): none of its 30000 readings lies within 0.4-30 m of the scanner");
  CHECK_FALSE(fs::exists(map));
  const auto wide = runCli("--quiet build --identity --min-range 0 --max-range 60 -o " + map + " " + scan);
  REQUIRE_MESSAGE(wide.exit_code == 0, wide.output);
  const auto bounds = infoOf(map)["bounds"];
  CHECK(bounds["max"][0].get<double>() - bounds["min"][0].get<double>() == doctest::Approx(6.0).epsilon(0.05));
  // The message names the limits that would map it.
  const auto refused = runCli("--quiet build --identity -o " + map + ".b " + scan);
  CHECK(mlmap::test::contains(refused.output, "--min-range 0 --max-range"));
  // label refuses the same scan under the same limits, where every point would be "none".
  REQUIRE(runCli("--quiet planes " + map + " -o " + map + ".l").exit_code == 0);
  checkOneLineError(runCli("--quiet label --identity " + map + ".l -o " + (dir / "far.labels.xyz").string() + " " + scan),
                    "far.xyz (scan 1): none of its");
  CHECK_FALSE(fs::exists(dir / "far.labels.xyz"));
  const auto labelled = runCli("--quiet label --identity --min-range 0 --max-range 60 " + map + ".l -o " +
                               (dir / "far.labels.xyz").string() + " " + scan);
  CHECK_MESSAGE(labelled.exit_code == 0, labelled.output);
  // calibrate too (it said "0 points lie below the sensor", as if no floor had been scanned).
  checkOneLineError(runCli("--quiet calibrate " + scan + " -o " + (dir / "mount.json").string()),
                    "far.xyz (scan 1): none of its 30000 readings lies within 0.4-30 m of the scanner");
  CHECK_FALSE(fs::exists(dir / "mount.json"));
}

TEST_CASE("CLI: a y-up cloud is warned about, and --up auto or --up y turns it z-up") {
  mlmap::test::TempDir dir;
  // An office of 10 × 8 m: floor and ceiling outweigh the walls, as in most rooms (a
  // corridor's walls do not, and are not warned about).
  const Eigen::Vector3d low(-4.0, -4.0, -1.0), high(6.0, 4.0, 1.5);
  mlmap::Scan room = roomScan(false, low, high);
  for (mlmap::Point& point : room.points) point = mlmap::Point(point.x(), point.z(), -point.y());  // z up -> y up
  const std::string scan = (dir / "yup.xyz").string(), map = (dir / "yup.mlmap").string();
  mlmap::io::writeXyz(scan, room);
  auto result = runCli("--quiet build --identity --no-octree -o " + map + " " + scan);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  CHECK(mlmap::test::contains(result.output, "warning: the data look y-up, not z-up"));
  CHECK(mlmap::test::contains(result.output, "--up y"));
  for (const char* up : {"auto", "y"}) {
    result = runCli("--quiet build --identity --no-octree --up " + std::string(up) + " -o " + map + " " + scan);
    REQUIRE_MESSAGE(result.exit_code == 0, result.output);
    CHECK_FALSE(mlmap::test::contains(result.output, "warning"));
    const auto bounds = infoOf(map)["bounds"];
    CHECK(bounds["max"][2].get<double>() - bounds["min"][2].get<double>() == doctest::Approx(2.5).epsilon(0.1));
    CHECK(bounds["min"][2].get<double>() == doctest::Approx(-1.0).epsilon(0.1));
  }
  // A z-up cloud gives no warning.
  mlmap::io::writeXyz(scan, roomScan(false, low, high));
  result = runCli("--quiet build --identity --no-octree -o " + map + " " + scan);
  CHECK_FALSE(mlmap::test::contains(result.output, "warning"));
}

TEST_CASE("CLI: a depth camera's organized cloud, y-up by its VIEWPOINT, is warned about and turned by --up auto") {
  // PCL's office1.pcd: a Kinect's 640 x 480 view whose far wall holds most planar cells;
  // until session 63 nothing warned and `--up auto` kept z (the wall's axis).
  mlmap::test::TempDir dir;
  const std::vector<Eigen::Vector3d> view =
      mlmap::test::cameraViewPoints(Eigen::Matrix3d::Identity(), 60000, {-2.0, -3.0, -1.0}, {4.0, 1.0, 1.5});
  const std::size_t columns = view.size() / 4;  // four image rows
  std::string text = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH " + std::to_string(columns) +
                     "\nHEIGHT 4\nVIEWPOINT 0 0 0 0 1 0 0\nPOINTS " + std::to_string(4 * columns) + "\nDATA ascii\n";
  for (std::size_t k = 0; k < 4 * columns; ++k)
    text += std::to_string(view[k].x()) + " " + std::to_string(view[k].y()) + " " + std::to_string(view[k].z()) + "\n";
  const std::string scan = (dir / "view.pcd").string(), map = (dir / "view.mlmap").string();
  mlmap::test::writeText(scan, text);
  auto result = runCli("--quiet build --no-octree -o " + map + " " + scan);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  CHECK(mlmap::test::contains(result.output, "warning: the data look y-up, not z-up (from the down of a depth camera's image"));
  result = runCli("build --no-octree --up auto -o " + map + " " + scan);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  CHECK(mlmap::test::contains(result.output, "up is +y"));
  // Turned z-up: the room's floor 1 m below the camera and its ceiling 1.5 m above.
  const auto bounds = infoOf(map)["bounds"];
  CHECK(bounds["min"][2].get<double>() == doctest::Approx(-1.0).epsilon(0.1));
  CHECK(bounds["max"][2].get<double>() < 1.6);
}

TEST_CASE("CLI: planes says when no floor is in view, and not when one is") {
  mlmap::test::TempDir dir;
  // A cloud cut above its floor (as Bobkov's room 2 is): a table top at 0.75 m, its legs'
  // and a cabinet's lower parts below it, no floor.
  mlmap::Scan cut;
  for (double x = 0.0; x <= 1.6; x += 0.01)
    for (double y = 0.0; y <= 0.8; y += 0.01) cut.points.emplace_back(x, y, 0.75);
  for (double x = -1.0; x <= 2.5; x += 0.01)
    for (double z = 0.05; z <= 0.45; z += 0.01) cut.points.emplace_back(x, -0.5, z);
  for (double y = -0.5; y <= 1.5; y += 0.01)
    for (double z = 0.05; z <= 0.45; z += 0.01) cut.points.emplace_back(-1.0, y, z);
  const std::string scan = (dir / "cut.xyz").string(), map = (dir / "cut.mlmap").string();
  mlmap::io::writeXyz(scan, cut);
  REQUIRE(runCli("--quiet build --identity --no-octree -o " + map + " " + scan).exit_code == 0);
  auto result = runCli("planes " + map);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  CHECK(mlmap::test::contains(result.output, "note: no floor in view"));
  CHECK(mlmap::test::contains(result.output, "no patch is classed floor, ceiling or table"));
  // Walls from the cut up: the table is measured from where they end.
  mlmap::Scan walled = cut;
  for (double x = -1.0; x <= 2.5; x += 0.01)
    for (double z = 0.45; z <= 2.0; z += 0.01) walled.points.emplace_back(x, -0.5, z);
  for (double y = -0.5; y <= 1.5; y += 0.01)
    for (double z = 0.45; z <= 2.0; z += 0.01) walled.points.emplace_back(-1.0, y, z);
  mlmap::io::writeXyz(scan, walled);
  REQUIRE(runCli("--quiet build --identity --no-octree -o " + map + " " + scan).exit_code == 0);
  result = runCli("planes " + map);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  CHECK(mlmap::test::contains(result.output, "measured from where the walls end below, z 0.0"));
  CHECK(mlmap::test::contains(result.output, " table "));
  mlmap::io::writeXyz(scan, roomScan(false));
  REQUIRE(runCli("--quiet build --identity --no-octree -o " + map + " " + scan).exit_code == 0);
  result = runCli("planes " + map);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  CHECK_FALSE(mlmap::test::contains(result.output, "no floor"));
}

TEST_CASE("CLI: label and register take --mount as build does") {
  RoomFiles room;
  mlmap::test::writeText(room.dir / "mount.json",
                         R"({"schema": "mlmap.mount/1", "roll_correction_deg": 0, "pitch_correction_deg": 90,)"
                         R"( "floor_distance": 1, "floor_points": 100})");
  const std::string mount = " --mount " + (room.dir / "mount.json").string();
  REQUIRE(runCli("--quiet build --identity -o " + room.map + mount + " " + room.scan).exit_code == 0);
  const std::string labelled = (room.dir / "labelled.mlmap").string();
  REQUIRE(runCli("--quiet planes " + room.map + " -o " + labelled).exit_code == 0);
  const std::string labels = (room.dir / "labels.xyz").string();
  const auto result = runCli("--quiet label --identity " + labelled + mount + " -o " + labels + " " + room.scan);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  // Pitched by 90 deg about y: x goes to -z.
  const mlmap::Scan input = mlmap::io::readXyz(room.scan);
  const mlmap::Scan written = mlmap::io::readXyz(labels);
  REQUIRE(written.size() == input.size());
  const mlmap::Point& p = input.points[1];
  CHECK((written.points[1] - mlmap::Point(p.z(), p.y(), -p.x())).norm() < 1e-3);
  CHECK(mlmap::test::contains(runCli("register --help").output, "--mount"));
}
