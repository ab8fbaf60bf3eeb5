// Internal to eRMSM, beyond the paper: the raster a patch's area and outline are measured
// on. Its cells are the grid's where the patch's blocks fill them; where the blocks lie
// further apart (a surface sampled sparser than the grid: a wall 8 m from the scanner at
// 10 cm cells is points 15 cm apart), the area counted cell by cell is only the cells its
// points happen to fall in (half of it) and the outline follows one piece of it, so the
// raster's cells are as wide as the blocks' spacing.
#pragma once

#include <cstdint>
#include <vector>

#include "mlmap/planes/block_grid.hpp"

namespace mlmap {

// Cells per raster cell for the blocks `blocks` (ascending ids) of one patch: their median
// distance to the nearest other block of theirs in cells (across between their points, up
// between their extents), rounded, from 1 to 3 (a median
// under 1.5 cells, a dense surface's, gives 1). Up to 256 blocks, evenly spread, are asked.
int spacingStep(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks);

}  // namespace mlmap
