// A staircase seen from its foot (issue 19, OctoMap's fr079 scan): a scanner near floor
// level sees each riser as a few scan lines and none of the treads. A plane tilted at the
// flight's slope passes within ε of every riser, and the detector laid one patch through
// all of them (fr079 at 10 cm cells: one 'other' patch 23° off level over its 13 steps).
// Such a patch is cut into its steps now (src/planes/stepped.hpp): each of its blocks
// holds a piece of one riser, spread along the ramp's normal by the riser's height, where
// a real ramp's blocks spread by the noise, and the ramp stays.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include "../src/planes/patch_rules.hpp"
#include "../src/planes/stepped.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/classify.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"
#include "patch_pieces.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

constexpr int kRisers = 10;
constexpr double kRise = 0.16;   // m
constexpr double kGoing = 0.28;  // m, riser to riser
constexpr double kFirst = 0.07;  // m, the first riser's x: off the cell boundaries
constexpr double kWidth = 4.0;   // m, along y
constexpr double kNoise = 0.008;
constexpr double kKappa = 25.0 * std::numbers::pi / 180.0;

double riserX(int k) { return kFirst + k * kGoing; }

// Each riser seen as `lines` scan lines `spacing` apart from 2 cm above its foot, a point
// every 6-10 cm along y, 8 mm of range noise (along x).
test::PlaneSceneBuilder risersFromBelow(double cell, unsigned seed, int lines = 5, double spacing = 0.03) {
  test::PlaneSceneBuilder scene(cell, kNoise, seed);
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, kNoise);
  std::uniform_real_distribution<double> gap(0.06, 0.10);
  for (int k = 0; k < kRisers; ++k) {
    for (int line = 0; line < lines; ++line) {
      const double z = k * kRise + 0.02 + line * spacing;
      for (double y = -kWidth / 2 + gap(random) / 2; y < kWidth / 2; y += gap(random)) {
        scene.map().insert(Point{riserX(k) + noise(random), y, z}, kNoise * kNoise);
      }
    }
  }
  return scene;
}

// Which riser block `id`'s points belong to (by their mean x), or -1.
int riserOf(const BlockGrid& grid, std::uint32_t id) {
  const double x = grid.pointsFrameOf(id).x() + grid.pointsOf(id).mean_x;
  for (int k = 0; k < kRisers; ++k) {
    if (std::abs(x - riserX(k)) < 0.1) return k;
  }
  return -1;
}

std::vector<std::uint32_t> allBlocks(const BlockGrid& grid) {
  std::vector<std::uint32_t> ids(grid.size());
  for (std::uint32_t id = 0; id < grid.size(); ++id) ids[id] = id;
  return ids;
}

// The flight's slope: its normal leans back from +x, rise over going.
Eigen::Vector3f rampNormal() { return Eigen::Vector3f(-kRise, 0.0F, kGoing).normalized(); }

// Step k's band as the cut leaves it: 4 m wide along y, from the riser's foot to its
// nosing (`height` m), leaning back 40° from plumb.
Plane band(int k, double height) {
  Plane plane;
  const double lean = 40.0 * std::numbers::pi / 180.0;
  plane.normal = Eigen::Vector3d(std::cos(lean), 0.0, -std::sin(lean));
  const Eigen::Vector3d foot(riserX(k), 0.0, k * kRise);
  const Eigen::Vector3d up_band = Eigen::Vector3d(std::sin(lean), 0.0, std::cos(lean)) * (height / std::cos(lean));
  plane.offset = -plane.normal.dot(foot);
  plane.outline = {foot + Eigen::Vector3d(0.0, -2.0, 0.0), foot + Eigen::Vector3d(0.0, 2.0, 0.0),
                   foot + up_band + Eigen::Vector3d(0.0, 2.0, 0.0), foot + up_band + Eigen::Vector3d(0.0, -2.0, 0.0)};
  plane.centroid = foot + 0.5 * up_band;
  plane.area = 4.0 * up_band.norm();
  return plane;
}

}  // namespace

TEST_CASE("Planes on stairs seen from below: bands a riser apart, three or more, are steps") {
  std::vector<Plane> flight;
  for (int k = 0; k < 4; ++k) flight.push_back(band(k, 0.14));
  std::vector<Plane> two(flight.begin(), flight.begin() + 2);
  std::vector<Plane> tall{band(0, 1.0), band(3, 1.0), band(6, 1.0)};  // no step's band: a metre tall
  classifyPlanes(flight);
  classifyPlanes(two);
  classifyPlanes(tall);
  for (const Plane& plane : flight) CHECK(plane.label == PlaneClass::Step);  // 'other' before
  for (const Plane& plane : two) CHECK(plane.label == PlaneClass::Other);
  for (const Plane& plane : tall) CHECK(plane.label == PlaneClass::Other);
}

TEST_CASE("Planes on stairs seen from below: a ramp through the risers is cut into one patch per riser") {
  for (const double cell : {0.05, 0.1}) {
    for (const unsigned seed : {1U, 2U}) {
      CAPTURE(cell);
      CAPTURE(seed);
      test::PlaneSceneBuilder scene = risersFromBelow(cell, seed);
      const BlockGrid grid(scene.map());
      PatchSet set;
      set.labels.assign(grid.size(), 0);
      test::addPatch(grid, set, allBlocks(grid), rampNormal(), kKappa, kNoise);
      REQUIRE(set.planes.size() == 1);
      const StepConfig config{kNoise, 6, 0.15};
      CHECK(splitSteps(grid, set, config) == 1);
      // Per riser, the patch holding most of its blocks holds them all and no other riser's.
      std::vector<std::set<std::int32_t>> patches_of(kRisers);
      std::vector<std::set<int>> risers_of(set.planes.size() + 1);
      for (std::uint32_t id = 0; id < grid.size(); ++id) {
        const int k = riserOf(grid, id);
        REQUIRE(k >= 0);
        patches_of[static_cast<std::size_t>(k)].insert(set.labels[id]);
        if (set.labels[id] > 0) risers_of[static_cast<std::size_t>(set.labels[id])].insert(k);
      }
      CHECK(set.planes.size() == kRisers);
      for (int k = 0; k < kRisers; ++k) {
        CAPTURE(k);
        const std::set<std::int32_t>& on = patches_of[static_cast<std::size_t>(k)];
        CHECK(on.size() == 1);
        CHECK(*on.begin() > 0);
        if (*on.begin() > 0) CHECK(risers_of[static_cast<std::size_t>(*on.begin())].size() == 1);
      }
      // Each step's plane is the riser's own: plumb within 10°, at its x within 2 cm.
      for (const Plane& plane : set.planes) {
        CAPTURE(plane.centroid.transpose());
        CHECK(std::abs(plane.normal.z()) < std::sin(10.0 * std::numbers::pi / 180.0));
        const int k = static_cast<int>(std::lround((plane.centroid.x() - kFirst) / kGoing));
        CHECK(std::abs(plane.centroid.x() - riserX(k)) < 0.02);
      }
    }
  }
}

TEST_CASE("Planes on stairs seen from below: a ramp over part of the flight's width leaves whole risers") {
  // At 5 cm cells fr079's ramps were pieces a metre or two wide of a flight 5 m wide: each
  // step grows along its band over the blocks of no patch, not into the next step's.
  for (const double cell : {0.05, 0.1}) {
    CAPTURE(cell);
    test::PlaneSceneBuilder scene = risersFromBelow(cell, 3);
    const BlockGrid grid(scene.map());
    std::vector<std::uint32_t> half;
    for (std::uint32_t id = 0; id < grid.size(); ++id) {
      if (grid.pointsFrameOf(id).y() < 0.0) half.push_back(id);
    }
    PatchSet set;
    set.labels.assign(grid.size(), 0);
    test::addPatch(grid, set, half, rampNormal(), kKappa, kNoise);
    CHECK(splitSteps(grid, set, StepConfig{kNoise, 6, 0.15}) == 1);
    CHECK(set.planes.size() == kRisers);
    // Per riser, its blocks on each patch (0: none).
    std::vector<std::map<std::int32_t, int>> on(kRisers);
    for (std::uint32_t id = 0; id < grid.size(); ++id) ++on[static_cast<std::size_t>(riserOf(grid, id))][set.labels[id]];
    std::set<std::int32_t> taken;
    for (int k = 0; k < kRisers; ++k) {
      CAPTURE(k);
      int blocks = 0;
      int largest = 0;
      std::int32_t id = 0;
      for (const auto& [patch, count] : on[static_cast<std::size_t>(k)]) {
        blocks += count;
        if (patch > 0 && count > largest) largest = count, id = patch;
      }
      // Nearly all of the riser, its far half too (on no patch before the growth; a
      // block of a point in its noise's tail beyond 3 σ stays off), on a patch of its own.
      CHECK(largest >= 0.95 * blocks);
      CHECK(on[static_cast<std::size_t>(k)].size() <= 2);
      CHECK(taken.insert(id).second);
    }
  }
}

TEST_CASE("Planes on stairs seen from below: a riser 0.14 m tall is no thin sliver at 10 cm cells") {
  // A wall face's height is its points' own, not a count of cells: the width rule (0.7 of
  // a cell) made a riser's strip, its blocks' tops and bottoms 7 cm either side of their
  // middle, a line of clutter at 10 cm cells, so no riser was ever a patch there. Up a wall
  // the least is now a riser's of 8 cm (ClassifyConfig::riser_min); a 3 cm strip stays thin.
  for (const double height : {0.14, 0.03}) {
    CAPTURE(height);
    test::PlaneSceneBuilder scene(0.1, 0.003, 6);
    scene.withNoise(0.003, 1e-5).rectangle({0.07, -1.5, 0.3}, {0.0, 3.0, 0.0}, {0.0, 0.0, height}, 0.01);
    const BlockGrid grid(scene.map());
    Patch patch;
    patch.blocks = allBlocks(grid);
    for (const std::uint32_t id : patch.blocks) patch.surface += grid.blocks()[id].surface;
    const CandidatePlane plane{Eigen::Vector3f::UnitX(), Eigen::Vector3f(0.07F, 0.0F, 0.37F)};
    CHECK(isThin(grid, patch, plane, 0.7 * 0.1) == (height < 0.08));  // the riser was thin before
  }
}

TEST_CASE("Planes on stairs seen from above: a ramp through the treads is cut into one level patch per tread") {
  // A scanner above the flight sees its treads, level and touching along the fall line
  // (no valley of points between them), and its risers between: the cut at the treads'
  // heights, each tread's riser blocks back to no patch. A generated stairwell seen from a
  // laser 0.3 m high at 10 cm cells (its first two treads and risers) was one 26° patch.
  constexpr int kTreads = 6;
  for (const double cell : {0.05, 0.1}) {
    CAPTURE(cell);
    test::PlaneSceneBuilder scene(cell, 0.003, 4);
    scene.withNoise(0.003, 1e-5);
    for (int k = 0; k < kTreads; ++k) {
      const double x = 0.07 + k * kGoing;
      scene.rectangle({x, -1.5, k * kRise}, {0.0, 3.0, 0.0}, {0.0, 0.0, kRise}, 0.02);            // riser
      scene.rectangle({x, -1.5, (k + 1) * kRise}, {kGoing, 0.0, 0.0}, {0.0, 3.0, 0.0}, 0.02);  // tread
    }
    const BlockGrid grid(scene.map());
    PatchSet set;
    set.labels.assign(grid.size(), 0);
    test::addPatch(grid, set, allBlocks(grid), rampNormal(), kKappa, 0.003);
    CHECK(splitSteps(grid, set, StepConfig{0.003, 6, 0.15}) == 1);
    REQUIRE(set.planes.size() == kTreads);
    std::set<int> heights;
    for (const Plane& plane : set.planes) {
      CAPTURE(plane.centroid.transpose());
      CHECK(plane.normal.normalized().z() > std::cos(5.0 * std::numbers::pi / 180.0));  // level, not the ramp's 30°
      const int k = static_cast<int>(std::lround(plane.centroid.z() / kRise)) - 1;
      CHECK(std::abs(plane.centroid.z() - (k + 1) * kRise) < 0.01);
      heights.insert(k);
      // Of its 0.84 m² (the top one 0.9), most at 5 cm cells; at 10 cm the cells that hold
      // a riser too are another surface's, and a tread keeps one or two rows of its three.
      // None of the next tread's.
      CHECK(plane.area > (cell < 0.07 ? 0.55 : 0.25));
      CHECK(plane.area < 1.0);
    }
    CHECK(heights.size() == kTreads);
  }
}

TEST_CASE("Planes on stairs seen from below: a real ramp's patch stays whole") {
  // A ramp 3 m long at the flight's slope (29.7°), sampled every 2 cm with the same noise:
  // its blocks spread along its normal by the noise, so it is no staircase.
  for (const double cell : {0.05, 0.1}) {
    CAPTURE(cell);
    test::PlaneSceneBuilder scene(cell, kNoise, 3);
    const Eigen::Vector3d up_the_ramp = Eigen::Vector3d(kGoing, 0.0, kRise).normalized() * 3.0;
    scene.withNoise(kNoise, kNoise * kNoise).rectangle({0.07, -1.5, 0.0}, up_the_ramp, {0.0, 3.0, 0.0}, 0.02);
    const BlockGrid grid(scene.map());
    PatchSet set;
    set.labels.assign(grid.size(), 0);
    test::addPatch(grid, set, allBlocks(grid), rampNormal(), kKappa, kNoise);
    CHECK(splitSteps(grid, set, StepConfig{kNoise, 6, 0.15}) == 0);
    REQUIRE(set.planes.size() == 1);
    CHECK(set.blocks.front().size() == grid.size());
  }
}

namespace {

// bench/stairs_bench.py's stairwell (a flight of 13 steps of 0.14 m on 0.30 m treads, 3 m
// wide, turned 4° to the grid) scanned by the simulated tilting laser from 1.2 m, two poses.
constexpr const char* kStairwellJson = R"({
  "name": "stairwell",
  "scan_pattern": {"field_of_view_deg": 270, "angular_step_deg": 0.25, "tilt_start_deg": -30, "tilt_end_deg": 40,
                   "tilt_step_deg": 0.5, "min_range": 0.023, "max_range": 30, "range_sigma": 0.01,
                   "mount_height": 1.2, "seed": 3},
  "odometry": {"translation_noise_per_m": 0.0, "yaw_noise_per_rad": 0.0, "yaw_noise_per_m": 0.0, "seed": 7},
  "poses": [{"x": 3.0, "y": 2.0, "yaw_deg": 4}, {"x": 1.0, "y": 2.3, "yaw_deg": 0}],
  "surfaces": [
    {"type": "rectangle", "name": "floor", "class": "floor", "min": [0, 0, 0], "max": [14, 4.5, 0]},
    {"type": "rectangle", "name": "ceiling", "class": "ceiling", "min": [0, 0, 5.0], "max": [14, 4.5, 5.0]},
    {"type": "rectangle", "name": "wall_west", "class": "wall", "min": [0, 0, 0], "max": [0, 4.5, 5.0], "facing": "+x"},
    {"type": "rectangle", "name": "wall_east", "class": "wall", "min": [14, 0, 0], "max": [14, 4.5, 5.0], "facing": "-x"},
    {"type": "rectangle", "name": "wall_south", "class": "wall", "min": [0, 0, 0], "max": [14, 0, 5.0], "facing": "+y"},
    {"type": "rectangle", "name": "wall_north", "class": "wall", "min": [0, 4.5, 0], "max": [14, 4.5, 5.0], "facing": "-y"},
    {"type": "stairs", "name": "flight", "start": [5.0, 0.6], "yaw_deg": 4, "width": 3.0, "steps": 13,
     "riser": 0.14, "tread": 0.30, "top_depth": 1.5}
  ]
})";

}  // namespace

TEST_CASE("Planes on stairs seen from above: a flight's ramp is not refused for its treads' and risers' directions") {
  // At 10 cm cells every direction window on a flight spans a tread and both its risers, so
  // the search seeds ramps only, and their blocks' directions (level treads, plumb risers,
  // tilted windows) spread past the 8° rule: bench/stairs_bench.py's stairwell seen from
  // 1.2 m found no tread. A ramp that cuts into three or more level treads is now kept, and
  // cut into them after the search: 0 -> 5 of its 12 treads below the landing with a level
  // patch of their own.
  const sim::Scene stairwell = sim::parseScene(kStairwellJson, "stairwell.json");
  MLMap map(0.1);
  for (sim::SimulatedScan& simulated : sim::simulate(stairwell)) {
    simulated.scan.variances.clear();  // as `mlmap build` maps points from a file: a scanner's 3 cm
    map.insertScan(simulated.scan);
  }
  const PlaneDetection detection = detectPlanes(map);
  // Level patches at the treads' heights (tread k at (k + 1) 0.14 m), each over one tread.
  std::set<int> treads;
  for (const Plane& plane : detection.planes) {
    if (plane.normal.normalized().z() < std::cos(5.0 * std::numbers::pi / 180.0) || plane.area > 1.5) continue;
    const int k = static_cast<int>(std::lround(plane.centroid.z() / 0.14)) - 1;
    if (k >= 0 && k < 12 && std::abs(plane.centroid.z() - (k + 1) * 0.14) < 0.03) treads.insert(k);
  }
  MESSAGE(treads.size() << " treads with a level patch of their own");
  CAPTURE(detection.planes.size());
  CHECK(treads.size() >= 4);
}
