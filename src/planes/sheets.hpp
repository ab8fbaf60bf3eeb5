// Internal to eRMSM: the sheets of an accepted plane's blocks. Its slab is ε thick
// on either side, and ε is wider than what separates parallel faces a few cm apart
// (OctoMap's fr079: a wall's lower face 8 cm in front of its upper one; a door frame
// proud of its wall): a plane between them matched both, and one patch took them. Over
// metres a surface may leave its plane by more than the noise (waviness, registration),
// but from one block to the next it moves by about the noise; at a step between two
// faces it jumps. So the blocks are split where neighbouring ones differ in their
// distance from the plane by more than the noise allows, before the patches are cut.
#pragma once

#include <algorithm>
#include <cstdint>
#include <numbers>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "plane_scorer.hpp"

namespace mlmap {

// m: the most two neighbouring blocks of one sheet may differ by in their
// distance from their plane: 3 standard deviations of the difference of two points'
// noise, 3 √2 σ, and at least a cell: a block is the mean of what its cell holds, and
// where that is a surface's edge or a second surface (a wall's foot, a corner) the mean
// moves by up to half a cell, two neighbours' in opposite directions. Measured on the
// simulated lab (4 mm noise): with 3 √2 σ alone it lost 0.09 don't-care F1 at 10 cm
// cells; with a cell, 5 and 10 cm are as without sheets, 2 cm still loses 0.02-0.05
// (open). fr079's faces (8-10 cm apart) part at 5 cm cells, not at 10 cm.
inline double sheetStep(double noise, double cell_size) { return std::max(3.0 * std::numbers::sqrt2 * noise, cell_size); }

// `blocks` (ascending) in groups connected through pairs of blocks in cells at most
// `radius` apart (Chebyshev) and at most `max_rise` apart in height whose distances
// from the plane, compared at their closest points, differ by at most `step`; each group
// ascending, in the order of their first block.
std::vector<std::vector<std::uint32_t>> sheetsOf(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                                 const CandidatePlane& plane, double step, int radius,
                                                 double max_rise);

}  // namespace mlmap
