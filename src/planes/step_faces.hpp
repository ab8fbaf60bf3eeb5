// Internal to eRMSM, beyond the paper: a wall patch that is two parallel faces a step
// apart. A wall's lower face a few cm in front of its upper one (a dado, a radiator cover,
// OctoMap's fr079: 7-10 cm), or a door set back in its wall, lies within ε of a plane leaning
// between the two, and a vertical block's direction is level whatever the lean, so neither
// the search's rules nor the crease split (creases.hpp: faces that turn) part them. Where a
// cell is finer than the step, the sheets do (sheets.hpp); at 10 cm cells the step between
// neighbouring blocks of one sheet may be a cell, and the faces came as one patch leaning
// 4.7° (fr079 with half its points, 10 cm cells). Their blocks' positions across the wall
// tell: two groups a step apart, each as flat as the noise, each covering its own stretch
// of the wall (an opaque face hides what lies behind it; a depth camera's layers of one
// far wall cover the same stretch each, and stay one surface).
#pragma once

#include <cstddef>
#include <vector>

#include "creases.hpp"
#include "patch_set.hpp"

namespace mlmap {

// Patch k's two faces (indices into set.blocks[k]) where it is a plumb patch whose blocks
// fall into two groups across it, by their points' mean (the cut that leaves the least
// scatter): the groups' means at least a sheet's step of the noise apart (3 √2 σ, no cell
// floor) and four times the blocks' scatter about them, each with a tenth of the patch's
// points or more and large enough for a face (tooSmallForFace), the smaller one's stretch
// of the plane at most a fifth shared with the larger's. None otherwise.
std::vector<std::vector<std::size_t>> stepFaces(const BlockGrid& grid, const PatchSet& set, std::size_t k,
                                                const CreaseConfig& config);

}  // namespace mlmap
