// Plane detection must not depend on how the building lies on the map grid (issue 19):
// a box room scanned by the simulator, axis-aligned and turned about z, its four walls
// each found as one patch with the true normal.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "mlmap/map/ml_map.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "mlmap/sim/placement.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"
#include "room_scenes.hpp"
#include "simulated_map.hpp"

using namespace mlmap;

namespace {

struct WallFinding {
  int patches = 0;             // patches lying on the wall (centroid within 10 cm, normal within 20 deg)
  double normal_error_deg = 180.0;  // of the largest of them
  double area_share = 0.0;     // its area over the wall's
};

// The room turned by `yaw_deg` about z (and moved by a fraction of a 5 cm cell, so its
// walls do not lie on cell boundaries), simulated, mapped in 5 cm cells; for every wall,
// the patches that lie on it.
std::vector<WallFinding> wallsOfTurnedRoom(double yaw_deg) {
  sim::Scene scene = sim::parseScene(test::kBoxRoomJson, "box_room.json");
  sim::transformScene(scene, sim::Placement{0.013, 0.021, yaw_deg});
  MLMap map = test::simulatedMap(scene, 0.05);
  const PlaneDetection detection = detectPlanes(map);
  std::vector<WallFinding> walls;
  for (const sim::GroundTruthPlane& truth : scene.ground_truth) {
    if (truth.surface_class != sim::SurfaceClass::Wall) continue;
    // A wall facing ±x (before the turn: |n_x| > |n_y| after it, below 45 deg) is 4 m long.
    const double wall_area = 2.5 * (std::abs(truth.normal.x()) > std::abs(truth.normal.y()) ? 4.0 : 6.0);
    WallFinding wall;
    double largest = 0.0;
    for (const Plane& patch : detection.planes) {
      const double along = std::abs(patch.normal.dot(truth.normal));
      if (std::abs(truth.normal.dot(patch.centroid) + truth.d) > 0.1 ||
          along < std::cos(20.0 * std::numbers::pi / 180.0))
        continue;
      ++wall.patches;
      if (patch.area > largest) {
        largest = patch.area;
        wall.normal_error_deg = std::acos(std::min(1.0, along)) * 180.0 / std::numbers::pi;
        wall.area_share = patch.area / wall_area;
      }
    }
    walls.push_back(wall);
  }
  return walls;
}

void checkEachWallOnePatch(double yaw_deg) {
  const std::vector<WallFinding> walls = wallsOfTurnedRoom(yaw_deg);
  REQUIRE(walls.size() == 4);
  for (std::size_t w = 0; w < walls.size(); ++w) {
    CAPTURE(w);
    CAPTURE(walls[w].patches);
    CAPTURE(walls[w].area_share);
    CHECK(walls[w].patches == 1);
    CHECK(walls[w].normal_error_deg < 2.0);
    CHECK(walls[w].area_share > 0.7);
  }
}

}  // namespace

TEST_CASE("Planes turned: a box room along the grid gives each wall one patch along its normal") {
  checkEachWallOnePatch(0.0);
}

// Failed before blocks kept their points' mean (issue 19): the two 6 m walls got no patch
// at 7 and 10 deg, the direction-vector window sitting in one straight run of a wall's
// cell staircase and snapping its directions to the grid's axis.
TEST_CASE("Planes turned: a box room turned 7 or 10 deg gives each wall one patch along its normal") {
  checkEachWallOnePatch(7.0);
  checkEachWallOnePatch(10.0);
}

// The shipped lab with 3 cm of range noise, turned 10 deg (bench/planes_sweep.py's noise3
// variant): each wall's points spread ±9 cm about it, σ (read mostly on the grazing floor and
// ceiling) is 1.4 cm and ε 5 cm, and the tails beyond ε, in the cell columns either side of a
// turned wall's staircase, were accepted as planes of their own 2° off the wall and 6-8 cm
// from it (1.3-1.7 cm RMS against the wall's 2.2 cm: more than half of it, so no noise tail
// by the spread test): two beside the east wall and two beside the north wall. A patch
// parallel to a wall within 3.5 times the wall's RMS now joins it where their joint fit says
// they are one surface. That passed with the search's seed 1 only: seeds 4, 5 and 7 left
// tails 7-10 cm off (4.9 of the wall's RMS, whose patch ends at ε); a piece that far with under
// a quarter of the points per unit of surface of the wall beside it is now a tail candidate too.
TEST_CASE("Planes turned: the lab with 3 cm of range noise, turned 10 deg, has no plane beside a wall") {
  sim::Scene scene = sim::loadScene(std::string(MLMAP_SOURCE_DIR) + "/maps/lab.json");
  scene.pattern.range_sigma = 0.03;
  sim::transformScene(scene, sim::Placement{0.0, 0.0, 10.0});
  MLMap map = test::simulatedMap(scene, 0.05);
  for (const int seed : {1, 4, 5, 7}) {
    CAPTURE(seed);
    ErmsmConfig config;
    config.seed = seed;
    const PlaneDetection detection = detectPlanes(map, config);
    int beside = 0;
    for (const sim::GroundTruthPlane& truth : scene.ground_truth) {
      if (truth.surface_class != sim::SurfaceClass::Wall) continue;
      for (const Plane& patch : detection.planes) {
        if (std::abs(patch.normal.dot(truth.normal)) < std::cos(12.0 * std::numbers::pi / 180.0)) continue;
        const double apart = std::abs(truth.normal.dot(patch.centroid) + truth.d);
        if (apart > 0.04 && apart < 0.1 && patch.block_count >= 20) {
          ++beside;
          MESSAGE("a patch " << apart << " m from a wall, " << patch.block_count << " blocks, RMS " << patch.rms);
        }
      }
    }
    CHECK(beside == 0);
  }
}
