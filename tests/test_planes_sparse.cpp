// Surfaces far from the scanner (issue 19, PCL's room scans): past 4-5 m a floor is
// lines of points 10 cm apart, the lines 0.35-0.7 m apart. No direction window holds
// two lines, so no plane matched those blocks and the floor's patch stopped where its
// scan lines thinned out (the far half of the room's floor on no patch, 11 % of its
// points). They join the patch whose plane they lie on across gaps nothing was seen
// past; a surface at the same height with the floor seen between stays apart.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

#include "mlmap/planes/ermsm.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

// Scan lines x = const, each a point every 0.1 m along y from 0 to 4 m, at `height`.
void sparseLines(MLMap& map, const std::vector<double>& xs, double height, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, 0.005);
  for (const double x : xs) {
    for (double y = 0.03; y < 4.0; y += 0.1) map.insert(Point{x + noise(random), y, height + noise(random)}, 9e-4);
  }
}

// Of the blocks beyond x, the share on plane `id`.
double shareBeyond(const MLMap& map, double x, std::int32_t id) {
  std::size_t all = 0, on = 0;
  for (std::size_t n = 0; n < map.cellCount(); ++n) {
    if (map.cellCenter(map.cellAt(n)).x() <= x) continue;
    for (const Block& block : map.blocksAt(n)) {
      ++all;
      on += block.plane == id ? 1 : 0;
    }
  }
  return all > 0 ? static_cast<double>(on) / static_cast<double>(all) : 0.0;
}

// The largest level patch at `height`, or none.
const Plane* levelAt(const PlaneDetection& detection, double height) {
  const std::vector<const Plane*> found = test::levelPatchesAt(detection, height);
  return found.empty() ? nullptr : found.front();
}

// A dense 4 x 4 m floor with a wall at its far edge's foot, and beyond it six sparse scan
// lines 0.35-0.55 m apart on the floor's plane.
void farFloor(test::PlaneSceneBuilder& scene, double cell, unsigned seed) {
  const double o = cell / 3.0;  // off the cell boundaries
  scene.withNoise(0.005, 9e-4).floor(o, o, 4.0 + o, 4.0 + o, 0.0).wallY(4.2, o, 4.0 + o, 0.0, 2.0);
  sparseLines(scene.map(), {4.35, 4.7, 5.1, 5.55, 6.05, 6.6}, 0.0, seed);
}

}  // namespace

TEST_CASE("eRMSM: a floor's far part, sparse scan lines 0.35-0.55 m apart, is on the floor's patch") {
  for (const double cell : {0.05, 0.1}) {
    for (const unsigned seed : {1U, 2U}) {
      CAPTURE(cell);
      CAPTURE(seed);
      test::PlaneSceneBuilder scene(cell, 0.005, seed);
      farFloor(scene, cell, seed);
      const PlaneDetection detection = detectPlanes(scene.map());
      const Plane* floor = levelAt(detection, 0.0);
      REQUIRE(floor != nullptr);
      CHECK(shareBeyond(scene.map(), 4.3, floor->id) > 0.9);
      // Without the growth, the lines are on no patch (as before).
      test::PlaneSceneBuilder again(cell, 0.005, seed);
      farFloor(again, cell, seed);
      ErmsmConfig off;
      off.sparse_gap = 0.0;
      const PlaneDetection before = detectPlanes(again.map(), off);
      const Plane* floor_before = levelAt(before, 0.0);
      REQUIRE(floor_before != nullptr);
      CHECK(shareBeyond(again.map(), 4.3, floor_before->id) < 0.5);
    }
  }
}

TEST_CASE("eRMSM: sparse lines at a desk's height with the floor seen between stay off the desk") {
  for (const double cell : {0.05, 0.1}) {
    CAPTURE(cell);
    test::PlaneSceneBuilder scene(cell, 0.005, 1);
    const double o = cell / 3.0;
    // A desk 0.75 m up, x 1-2.5; the floor all round, the ceiling over it; beyond the
    // desk, 0.45 m on, two sparse lines at the desk's height (a shelf's edges): the floor
    // below the gap was seen.
    scene.withNoise(0.005, 9e-4)
        .floor(o, o, 4.0 + o, 4.0 + o, 0.0)
        .floor(o, o, 4.0 + o, 4.0 + o, 2.6)
        .floor(1.0 + o, 0.5 + o, 2.5 + o, 3.5 + o, 0.75);
    sparseLines(scene.map(), {3.0, 3.4}, 0.75, 1);
    const PlaneDetection detection = detectPlanes(scene.map());
    const Plane* desk = levelAt(detection, 0.75);
    REQUIRE(desk != nullptr);
    CHECK(shareBeyond(scene.map(), 2.9, desk->id) == 0.0);
  }
}
