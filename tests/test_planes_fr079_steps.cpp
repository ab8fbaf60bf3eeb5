// OctoMap's scan.dat (building 079, Freiburg; Debian's liboctomap-dev ships it) sees a
// flight of 13 steps from near floor level: each step a band of scan lines on its riser
// and nosing, the bands a step's going apart. At 10 cm cells the search lays a ramp
// through them, which is cut into its steps (src/planes/stepped.hpp). At 5 cm cells the
// ramp's blocks were split into connected pieces two cells apart, that is into its bands
// and the bands into their pieces between the balusters' shadows: pieces under a patch's
// size were dropped and the others kept the ramp's plane, so no ramp was left to cut (in
// this test's build, 4 of the 13 bands held a step patch). A ramp whose blocks are a
// staircase now stays whole across a step's going until its steps are cut (11 of 13).
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "helpers.hpp"

namespace {

struct Band {
  double x_low, x_high, z_low, z_high;  // m, in scan.dat's frame
};

// The 13 bands as bench/annotations/fr079.json marks them (its boxes span y -4.1..1.2).
constexpr std::array<Band, 13> kBands{{{5.28, 5.56, -0.05, 0.15},
                                       {5.58, 5.90, 0.10, 0.29},
                                       {5.93, 6.27, 0.23, 0.42},
                                       {6.28, 6.62, 0.38, 0.57},
                                       {6.63, 6.93, 0.53, 0.72},
                                       {6.93, 7.27, 0.65, 0.82},
                                       {7.28, 7.58, 0.80, 0.99},
                                       {7.62, 7.93, 0.95, 1.12},
                                       {7.97, 8.27, 1.08, 1.25},
                                       {8.28, 8.62, 1.23, 1.40},
                                       {8.63, 8.97, 1.38, 1.57},
                                       {8.98, 9.28, 1.53, 1.70},
                                       {9.32, 9.58, 1.68, 1.85}}};

// fr079's planes JSON at `cell` m, the scan moved by `shift` (x y, m) through a pose file or
// left where it is (--identity) without one; nullopt, with a message, where liboctomap-dev's
// example file is absent.
std::optional<nlohmann::json> fr079Planes(double cell, const std::string& shift = "") {
  const std::filesystem::path scan = mlmap::test::octomapExampleDir() / "scan.dat.bz2";
  if (!std::filesystem::exists(scan)) {
    MESSAGE("skipped: " << scan.string() << " is not present (liboctomap-dev's example data)");
    return std::nullopt;
  }
  const mlmap::test::TempDir dir;
  const std::string xyz = (dir.path() / "scan.xyz").string();
  REQUIRE(std::system(("bzip2 -dc '" + scan.string() + "' > '" + xyz + "'").c_str()) == 0);
  std::string placement = "--identity";
  if (!shift.empty()) {
    const std::string poses = (dir.path() / "moved.tum").string();
    mlmap::test::writeText(poses, "0 " + shift + " 0 0 0 0 1\n");
    placement = "--poses '" + poses + "'";
  }
  const std::string map = (dir.path() / "fr079.mlmap").string();
  const std::string planes = (dir.path() / "planes.json").string();
  const auto built = mlmap::test::runCli("-q build '" + xyz + "' " + placement + " --cell-size " + std::to_string(cell) +
                                         " --no-octree -o '" + map + "'");
  REQUIRE_MESSAGE(built.exit_code == 0, built.output);
  const auto detected = mlmap::test::runCli("-q planes '" + map + "' --threads 2 --seed 1 --json '" + planes + "' -o '" +
                                            (dir.path() / "planes.mlmap").string() + "'");
  REQUIRE_MESSAGE(detected.exit_code == 0, detected.output);
  std::ifstream file(planes);
  return nlohmann::json::parse(file);
}

}  // namespace

TEST_CASE("Planes on fr079's flight seen from below: at 5 cm cells most bands are a step") {
  const auto detected = fr079Planes(0.05);
  if (!detected) return;
  const nlohmann::json& json = *detected;
  int with_step = 0;
  for (const Band& band : kBands) {
    bool found = false;
    for (const auto& plane : json["planes"]) {
      const auto& c = plane["centroid"];
      const double x = c[0], y = c[1], z = c[2];
      found |= plane["label"] == "step" && x > band.x_low - 0.02 && x < band.x_high + 0.02 && y > -4.1 && y < 1.2 &&
               z > band.z_low - 0.02 && z < band.z_high + 0.02;
    }
    with_step += found ? 1 : 0;
  }
  MESSAGE(with_step << " of 13 bands hold a step patch");
  // 4 of 13 before (seed 1), 11 since.
  CHECK(with_step >= 10);
}

TEST_CASE("Planes on fr079's flight at 10 cm cells moved by a fraction of a cell: no merge joins its steps again") {
  // The crease split's merge pass (src/planes/ermsm.cpp) ran over every patch, and with the
  // scan moved by 1.3 and 2.7 cm across the grid it joined the steps cut from one ramp:
  // steps 7 and 8 into one patch 0.68 m along the flight, steps 10 to 12 into a 2.4 m² ramp
  // again (4 step patches were left). The steps of one ramp now stay apart (8 step patches,
  // each under 0.5 m along the flight).
  const auto detected = fr079Planes(0.1, "0.013 0.027");
  if (!detected) return;
  const nlohmann::json& json = *detected;
  int steps = 0;
  double longest = 0.0;  // m along the flight (x)
  for (const auto& plane : json["planes"]) {
    const auto& c = plane["centroid"];
    const double x = c[0], y = c[1];
    if (plane["label"] != "step" || x < 5.2 || x > 9.7 || y < -4.2 || y > 1.3) continue;
    double low = 1e9, high = -1e9;
    for (const auto& vertex : plane["outline"]) {
      low = std::min(low, vertex[0].get<double>());
      high = std::max(high, vertex[0].get<double>());
    }
    ++steps;
    longest = std::max(longest, high - low);
  }
  MESSAGE(steps << " step patches on the flight, the longest " << longest << " m along it");
  CHECK(steps >= 7);
  CHECK(longest < 0.55);
}
