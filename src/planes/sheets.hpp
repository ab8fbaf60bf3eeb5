// Internal to eRMSM: the sheets of an accepted plane's blocks. Its slab is ε thick
// on either side, and ε is wider than what separates parallel faces a few cm apart
// (OctoMap's fr079: a wall's lower face 8 cm in front of its upper one; a door frame
// proud of its wall): a plane between them matched both, and one patch took them. Over
// metres a surface may leave its plane by more than the noise (waviness, registration),
// but from one block to the next it moves by about the noise; at a step between two
// faces it jumps. So the blocks are split where neighbouring ones differ in their
// distance from the plane by more than the noise allows, before the patches are cut.
#pragma once

#include <cstdint>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "plane_scorer.hpp"

namespace mlmap {

// `blocks` (ascending) in groups connected through pairs of blocks in cells at most
// `radius` apart (Chebyshev) and at most `max_rise` apart in height whose distances
// from the plane, compared at their closest points, differ by at most `step`; each group
// ascending, in the order of their first block.
std::vector<std::vector<std::uint32_t>> sheetsOf(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                                 const CandidatePlane& plane, double step, int radius,
                                                 double max_rise);

}  // namespace mlmap
