// Internal to eRMSM: the patch split hands each patch the raster its outline is traced
// on. Both rasterise the same blocks on the same plane (the one the patch was split
// on), so a patch's outline needs neither its footprints nor their sort again: for a
// floor or a ceiling at 2 cm those were most of its outline's cost.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/patches.hpp"

namespace mlmap {

// Raster cells (u, v) of a plane's raster with v in [v_low, v_high].
struct Segment {
  std::int32_t u;
  std::int32_t v_low;
  std::int32_t v_high;
};

struct SplitPatches {
  std::vector<Patch> patches;  // as splitIntoPatches returns them
  // Per patch, its raster cells as runs of touching cells, column by column: what
  // outlineOf rasterises from its blocks (empty for a split at gap 0).
  std::vector<std::vector<Segment>> outline_runs;
};

SplitPatches splitWithOutlineRuns(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                  const Eigen::Vector3d& normal, const Eigen::Vector3d& point, int gap_cells,
                                  int threads);

// outlineOf(grid, blocks, normal, point) from the blocks' runs.
std::vector<Eigen::Vector3d> outlineOfRuns(const std::vector<Segment>& runs, double cell_size,
                                           const Eigen::Vector3d& normal, const Eigen::Vector3d& point);

// The runs outlineOf traces: the blocks' raster cells, `step` map cells wide.
std::vector<Segment> runsOf(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                            const Eigen::Vector3d& normal, const Eigen::Vector3d& point, int step);

// The four corners of every run on the plane: their box holds every cell of every piece of
// a patch, where its outline rounds the largest piece only.
std::vector<Eigen::Vector3d> cornersOfRuns(const std::vector<Segment>& runs, double cell_size,
                                           const Eigen::Vector3d& normal, const Eigen::Vector3d& point);

}  // namespace mlmap
