// Hand-cut patches for the tests of eRMSM's patch stage (src/planes/patch_set.hpp, internal):
// a patch of given blocks, described on its own plane, as the search leaves its patches.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "../src/planes/patch_set.hpp"
#include "mlmap/planes/block_grid.hpp"

namespace mlmap::test {

// Appends the patch of `blocks` (ascending) to `set` (its labels sized to the grid),
// fitted from `normal` (unit) through its first block, with id set.planes.size() + 1.
inline void addPatch(const BlockGrid& grid, PatchSet& set, std::vector<std::uint32_t> blocks,
                     const Eigen::Vector3f& normal, double kappa_rad, double noise) {
  Patch patch;
  patch.blocks = std::move(blocks);
  for (const std::uint32_t id : patch.blocks) patch.surface += grid.blocks()[id].surface;
  const CandidatePlane reference{normal, grid.blocks()[patch.blocks.front()].point};
  Plane plane = describePatch(grid, patch, reference, kappa_rad, noise);
  plane.id = static_cast<std::int32_t>(set.planes.size() + 1);
  for (const std::uint32_t id : patch.blocks) set.labels[id] = plane.id;
  set.planes.push_back(plane);
  set.blocks.push_back(patch.blocks);
  set.outline_frames.push_back(OutlineFrame{plane.normal, plane.centroid, true});
  set.outline_runs.emplace_back();
}

}  // namespace mlmap::test
