// A patch's plane from the blocks that hold one surface (describePatch). At 10 cm cells the
// cells along a top's edge also hold what lies just below it (a rim, a bevel, the panel's
// top), fused into its level blocks; fitted to all of its blocks' points the top's plane
// leaned towards them (bench/real_data.py at 10 cm: fr079's upper wall face leaned towards
// the lower face 8-10 cm in front of it and the two became one patch; ANYmal's treads' RMS).
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "../src/planes/patch_set.hpp"
#include "mlmap/planes/block_grid.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

TEST_CASE("describePatch: a top's plane leaves out the edge blocks that hold a bevel below it") {
  for (const unsigned seed : {1U, 2U}) {
    CAPTURE(seed);
    const double cell = 0.1;
    const double o = cell / 3.0;
    test::PlaneSceneBuilder scene(cell, 0.008, seed);
    scene.withNoise(0.008, 9e-4)
        .floor(1.0 + o, 1.0 + o, 2.6 + o, 1.8 + o, 0.75)  // the top
        // A bevel along its front edge, 6 cm deep, down to 5 cm below the top: in the front
        // row's cells, within their level blocks.
        .rectangle({1.0 + o, 1.0 + o, 0.70}, {1.6, 0.0, 0.0}, {0.0, 0.06, 0.05});
    const BlockGrid grid(scene.map());
    Patch top;
    for (std::uint32_t id = 0; id < grid.size(); ++id) {
      if (!grid.blocks()[id].vertical) top.blocks.push_back(id);
    }
    REQUIRE(top.blocks.size() > 100);
    const CandidatePlane reference{Eigen::Vector3f::UnitZ(), Eigen::Vector3f(1.8F, 1.4F, 0.75F)};
    const Plane plane = describePatch(grid, top, reference, 25.0 * std::numbers::pi / 180.0, 0.008);
    const Eigen::Vector3d normal = plane.normal.normalized();
    CHECK(std::acos(std::abs(normal.z())) * 180.0 / std::numbers::pi < 0.2);
    CHECK(std::abs(std::abs(plane.offset) - 0.75) < 0.003);
    CHECK(plane.rms < 0.011);  // the top's own 8 mm, not the bevel's
  }
}
