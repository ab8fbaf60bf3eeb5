// The raster a patch's area and outline are measured on (src/planes/raster_step.hpp): the
// grid's cells where the blocks fill them, cells as wide as their spacing where they lie
// further apart. Its first version measured the distance between blocks' points in 3D,
// and a dense wall whose cell columns end at different heights (a door, a cabinet in front)
// read as sparse: their tall blocks' mid-heights lie far apart though the blocks touch.
#include <doctest/doctest.h>

#include <numeric>
#include <vector>

#include "../src/planes/raster_step.hpp"
#include "mlmap/map/ml_map.hpp"
#include "mlmap/planes/block_grid.hpp"

using namespace mlmap;

namespace {

const BlockGridConfig kConfig{.stack_gap = 0.06, .level_band = 0.05};

std::vector<std::uint32_t> allBlocks(const BlockGrid& grid) {
  std::vector<std::uint32_t> ids(grid.size());
  std::iota(ids.begin(), ids.end(), 0U);
  return ids;
}

// A level square of `side` m at height 0, a point every `spacing` m, off the cell boundaries.
MLMap levelLattice(double cell, double side, double spacing) {
  MLMap map(cell);
  for (double x = 0.013; x < side; x += spacing) {
    for (double y = 0.017; y < side; y += spacing) map.insert(Point(x, y, 0.0), 1e-4);
  }
  return map;
}

}  // namespace

TEST_CASE("spacingStep: a dense surface keeps the grid's cells, a lattice twice as wide gets cells twice as wide") {
  const BlockGrid dense(levelLattice(0.05, 1.0, 0.01), kConfig);
  CHECK(spacingStep(dense, allBlocks(dense)) == 1);
  const BlockGrid sparse(levelLattice(0.05, 1.0, 0.1), kConfig);
  CHECK(spacingStep(sparse, allBlocks(sparse)) == 2);
  const BlockGrid sparser(levelLattice(0.05, 1.5, 0.15), kConfig);
  CHECK(spacingStep(sparser, allBlocks(sparser)) == 3);
}

TEST_CASE("spacingStep: a dense wall whose columns end at different heights keeps the grid's cells") {
  // Cell columns along x = 1 side by side, 5 cm apart, alternately 2 m and 0.6 m tall:
  // their mid-heights lie 0.7 m apart, their extents overlap.
  MLMap map(0.05);
  for (int column = 0; column < 40; ++column) {
    const double y = 0.025 + 0.05 * column;
    const double top = column % 2 == 0 ? 2.0 : 0.6;
    for (double z = 0.0; z <= top; z += 0.01) map.insert(Point(1.013, y, z), 1e-4);
  }
  const BlockGrid grid(map, kConfig);
  REQUIRE(grid.size() == 40);
  CHECK(grid.blocks()[0].vertical);
  CHECK(spacingStep(grid, allBlocks(grid)) == 1);
}
