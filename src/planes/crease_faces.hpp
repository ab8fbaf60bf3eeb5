// Internal to eRMSM: the faces of one patch that meets itself at shallow creases (see
// creases.hpp). Faces grow from the blocks' direction windows (their points and their patch
// neighbours' within a cell), then every block goes to the nearest face near it, and the
// faces are refitted to their blocks until they stay the same.
#pragma once

#include <cstddef>
#include <vector>

#include "creases.hpp"
#include "patch_set.hpp"

namespace mlmap {

// Whether blocks of this many and this surface (surface units) are too few for a face:
// under the patch minimum in blocks, or under half of its minimum area.
bool tooSmallForFace(std::size_t blocks, double surface, double cell_size, const CreaseConfig& config);

// Patch k's faces (indices into set.blocks[k]), or none where one plane explains it: fewer
// than two faces, none creased against a neighbour, or the faces' residuals not a quarter
// of the one plane's with 85 % of its points on them (the rules of splitCreases).
std::vector<std::vector<std::size_t>> creaseFaces(const BlockGrid& grid, const PatchSet& set, std::size_t k,
                                                  const CreaseConfig& config);

}  // namespace mlmap
