// The mlmap CLI end to end: simulate -> build -> info, and one clear line for bad input.
#include <doctest/doctest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "helpers.hpp"

using mlmap::test::runCli;

namespace {

// A 4 × 3 × 2.5 m box room scanned from two poses with a coarse pattern: seconds, not minutes.
const char* kBoxRoom = R"({
  "name": "box room",
  "scan_pattern": {"tilt_start_deg": -60, "tilt_end_deg": 60, "tilt_step_deg": 2,
                   "angular_step_deg": 1, "range_sigma": 0.005, "mount_height": 0.6},
  "poses": [{"x": 1.5, "y": 1.5, "yaw_deg": 0}, {"x": 2.5, "y": 1.5, "yaw_deg": 90}],
  "surfaces": [
    {"type": "box", "min": [0, 0, 0], "max": [4, 3, 2.5], "class": "wall",
     "classes": {"bottom": "floor", "top": "ceiling"}}
  ]
})";

std::size_t lineCount(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

}  // namespace

TEST_CASE("CLI: --help on every subcommand, and an unknown subcommand fails") {
  for (const char* command : {"", "simulate ", "build ", "info ", "planes ", "label ", "merge ", "export ", "register "}) {
    const auto result = runCli(std::string(command) + "--help");
    CHECK(result.exit_code == 0);
    CHECK(result.output.find("Usage") != std::string::npos);
  }
  CHECK(runCli("frobnicate").exit_code != 0);
}

TEST_CASE("CLI: the lab scene goes from simulate to build to info") {
  mlmap::test::TempDir dir;
  const std::string scene = (mlmap::test::sourceDir() / "maps" / "lab.json").string();
  const std::string out = (dir / "lab").string();
  auto result = runCli("--quiet simulate " + scene + " -o " + out);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  CHECK(std::filesystem::exists(dir / "lab" / "scan_007.xyz"));
  CHECK(std::filesystem::exists(dir / "lab" / "poses_odom.txt"));
  std::string scans;
  for (int k = 0; k < 8; ++k) scans += " " + out + "/scan_00" + std::to_string(k) + ".xyz";
  result = runCli("--quiet build -o " + out + "/lab.mlmap --cell-size 0.1 --poses " + out +
                  "/poses_true.txt" + scans);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  result = runCli("info --json " + out + "/lab.mlmap");
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  const auto info = nlohmann::json::parse(result.output);
  CHECK(info["cells"].get<int>() > 5000);  // 8.3 × 11.4 m at 0.1 m is ~9,500 cells
  CHECK(info["blocks"]["vertical"].get<int>() > 500);
  CHECK(info["bounds"]["max"][0].get<double>() - info["bounds"]["min"][0].get<double>() ==
        doctest::Approx(8.3).epsilon(0.05));
  CHECK(info["bounds"]["max"][1].get<double>() - info["bounds"]["min"][1].get<double>() ==
        doctest::Approx(11.4).epsilon(0.05));
  CHECK(info["octree"]["occupied_leaves"].get<int>() > 1000);
  // register --report: the per-scan figures as JSON, every scan of the lab verified (its walls
  // hold every turn), none taken from its floor (only unconstrained results are).
  result = runCli("--quiet register --poses " + out + "/poses_odom.txt -o " + out + "/poses_icp.txt --report " + out +
                  "/report.json" + scans);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  std::ifstream report_file(out + "/report.json");
  const auto report = nlohmann::json::parse(report_file);
  REQUIRE(report["scans"].size() == 8);
  for (std::size_t k = 1; k < 8; ++k) {
    const auto& scan = report["scans"][k];
    CAPTURE(k);
    CHECK(scan["verified"].get<bool>());
    CHECK_FALSE(scan["levelled_on_floor"].get<bool>());
    CHECK(scan["rotation_eigenvalue_ratio"].get<double>() >= 7.5e-3);
    // Per kind of surface: both matched, both within twice the expected residual.
    const double expected = scan["expected_residual_m"].get<double>();
    for (const char* kind : {"level_surfaces", "upright_surfaces"}) {
      CAPTURE(kind);
      CHECK(scan[kind]["matched"].get<int>() > 100);
      CHECK(scan[kind]["residual_spread_m"].get<double>() <= 2.0 * expected);
    }
  }
}

TEST_CASE("CLI: bad input ends with one line naming the file, exit code 1, no output file") {
  mlmap::test::TempDir dir;
  mlmap::test::writeText(dir / "room.json", kBoxRoom);
  auto result = runCli("--quiet simulate " + (dir / "room.json").string() + " -o " +
                       (dir / "room").string());
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  const std::string scans =
      (dir / "room" / "scan_000.xyz").string() + " " + (dir / "room" / "scan_001.xyz").string();
  const std::string map = (dir / "map.mlmap").string();

  SUBCASE("a pose file with fewer poses than scans") {
    mlmap::test::writeText(dir / "one.txt", "0 0 0 0 0 0 0 1\n");
    result = runCli("--quiet build -o " + map + " --poses " + (dir / "one.txt").string() + " " + scans);
    CHECK(result.exit_code == 1);
    CHECK(lineCount(result.output) == 1);
    CHECK(result.output.find("one.txt") != std::string::npos);
  }
  SUBCASE("a scan with a NaN on line 3") {
    mlmap::test::writeText(dir / "bad.xyz", "0 0 0\n1 1 1\n1 nan 1\n");
    result = runCli("--quiet build --identity -o " + map + " " + (dir / "bad.xyz").string());
    CHECK(result.exit_code == 1);
    CHECK(lineCount(result.output) == 1);
    CHECK(result.output.find("bad.xyz:3") != std::string::npos);
  }
  SUBCASE("a damaged map") {
    mlmap::test::writeText(dir / "junk.mlmap", "not a map at all");
    result = runCli("info " + (dir / "junk.mlmap").string());
    CHECK(result.exit_code == 1);
    CHECK(lineCount(result.output) == 1);
    CHECK(result.output.find("junk.mlmap") != std::string::npos);
  }
  SUBCASE("a scene with a negative size") {
    mlmap::test::writeText(dir / "neg.json", R"({"poses": [{"x": 0, "y": 0}], "surfaces": [
      {"type": "box", "min": [0, 0, 0], "max": [-1, 3, 2]}]})");
    result = runCli("--quiet simulate " + (dir / "neg.json").string() + " -o " + (dir / "neg").string());
    CHECK(result.exit_code == 1);
    CHECK(result.output.find("neg.json") != std::string::npos);
  }
  CHECK_FALSE(std::filesystem::exists(map));
  // A good build over the same scans works.
  result = runCli("--quiet build -o " + map + " --poses " + (dir / "room" / "poses_true.txt").string() +
                  " " + scans);
  CHECK_MESSAGE(result.exit_code == 0, result.output);
  CHECK(std::filesystem::exists(map));
}
