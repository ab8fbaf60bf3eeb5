// A wall's lower face a few cm in front of its upper one (OctoMap's fr079: 7-10 cm; a dado,
// a radiator cover), at 10 cm cells: a plane leaning between the faces holds both within ε,
// every vertical block's direction is level whatever the lean, and the crease split (faces
// that turn) sees one face. With half of fr079's points the two came as one patch leaning
// 4.7°. Its blocks' positions across the wall are two groups a step apart, each on its own
// stretch of the wall: two patches. A depth camera's layers of one far wall cover the same
// stretch each and stay one patch.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "../src/planes/crease_faces.hpp"
#include "../src/planes/creases.hpp"
#include "mlmap/planes/block_grid.hpp"
#include "patch_pieces.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

const double kKappa = 25.0 * std::numbers::pi / 180.0;
const CreaseConfig kConfig{.noise = 0.01, .epsilon = 0.05, .kappa_rad = kKappa, .min_blocks = 6, .min_area = 0.15};

// Every vertical block of the grid as one patch, described from a plumb normal along y.
PatchSet wholeWall(const BlockGrid& grid) {
  PatchSet set;
  set.labels.assign(grid.size(), 0);
  std::vector<std::uint32_t> blocks;
  for (std::uint32_t id = 0; id < grid.size(); ++id)
    if (grid.blocks()[id].vertical) blocks.push_back(id);
  test::addPatch(grid, set, std::move(blocks), Eigen::Vector3f::UnitY(), kKappa, kConfig.noise);
  return set;
}

}  // namespace

TEST_CASE("Step faces: a wall's lower face 8 cm in front of its upper one is two patches at 10 cm cells") {
  for (const unsigned seed : {1U, 2U, 3U}) {
    CAPTURE(seed);
    test::PlaneSceneBuilder scene(0.1, 0.01, seed);
    scene.wallY(0.033, 0.0, 2.0, 0.0, 0.56).wallY(0.113, 0.0, 2.0, 0.62, 2.0);
    const BlockGrid grid(scene.map());
    PatchSet set = wholeWall(grid);
    REQUIRE(set.planes.size() == 1);
    CHECK(set.planes[0].rms > 1.5 * kConfig.noise);        // rough: looked at
    CHECK(creaseFaces(grid, set, 0, kConfig).empty());      // no crease parts the faces
    splitCreases(grid, set, kConfig);
    REQUIRE(set.planes.size() == 2);
    // Each face's blocks (by their points' mean across the wall: the cell rows either side
    // of y = 0.1) on a patch of their own.
    for (const bool lower : {true, false}) {
      CAPTURE(lower);
      std::vector<int> on(3, 0);
      int face_blocks = 0;
      for (std::uint32_t id = 0; id < grid.size(); ++id) {
        if (!grid.blocks()[id].vertical || (grid.blocks()[id].point.y() < 0.1) != lower) continue;
        ++face_blocks;
        ++on[static_cast<std::size_t>(std::clamp(set.labels[id], 0, 2))];
      }
      CHECK(std::max(on[1], on[2]) >= 0.9 * face_blocks);
    }
    CHECK(set.planes[0].normal.dot(set.planes[1].normal) > std::cos(5.0 * std::numbers::pi / 180.0));
    for (std::size_t k = 0; k < set.planes.size(); ++k)
      for (const std::uint32_t id : set.blocks[k]) CHECK(set.labels[id] == set.planes[k].id);
  }
}

TEST_CASE("Step faces: two layers of one far wall over the same stretch stay one patch") {
  test::PlaneSceneBuilder scene(0.1, 0.01, 1);
  scene.wallY(0.033, 0.0, 2.0, 0.0, 2.0).wallY(0.143, 0.0, 2.0, 0.0, 2.0);
  const BlockGrid grid(scene.map());
  PatchSet set = wholeWall(grid);
  REQUIRE(set.planes.size() == 1);
  CHECK(set.planes[0].rms > 1.5 * kConfig.noise);
  CHECK(creaseFaces(grid, set, 0, kConfig).empty());
  splitCreases(grid, set, kConfig);
  CHECK(set.planes.size() == 1);
}
