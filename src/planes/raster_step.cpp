#include "raster_step.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "median.hpp"

namespace mlmap {

int spacingStep(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks) {
  if (blocks.size() < 2) return 1;
  const double cell = grid.cellSize();
  // Looked for within two cells: a block with none nearer counts as three cells apart.
  constexpr int kReach = 2;
  constexpr std::size_t kSamples = 256;
  const std::size_t stride = std::max<std::size_t>(1, blocks.size() / kSamples);
  const std::size_t samples = (blocks.size() + stride - 1) / stride;
  // Cells: a nearest block closer than this rounds to one cell.
  const double near_cells = 1.5;
  std::vector<float> nearest;
  nearest.reserve(samples);
  std::size_t near = 0;
  const auto closest = [&](std::uint32_t id, int reach) {
    const PlaneBlock& block = grid.blocks()[id];
    float best = static_cast<float>((kReach + 1) * cell);
    float best_squared = best * best;
    grid.forEachNeighbour(block.cell, reach, [&](std::uint32_t other) {
      // Across, between their points; up, between their extents (a wall's blocks are tall,
      // their mid-heights say nothing of how far apart they are).
      const PlaneBlock& next = grid.blocks()[other];
      const float up = std::max({0.0F, next.bottom - block.top, block.bottom - next.top});
      const float squared = (next.point.head<2>() - block.point.head<2>()).squaredNorm() + up * up;
      if (squared >= best_squared || other == id || !std::binary_search(blocks.begin(), blocks.end(), other)) return;
      best_squared = squared;
    });
    best = std::sqrt(best_squared);
    return best / cell;
  };
  for (std::size_t k = 0; k < blocks.size(); k += stride) {
    // Most blocks of a dense surface have a neighbour in the cells round their own.
    double cells = closest(blocks[k], 1);
    if (cells >= near_cells) cells = closest(blocks[k], kReach);
    near += cells < near_cells ? 1 : 0;
    // More than half the samples one cell apart: the median is one cell.
    if (2 * near > samples) return 1;
    nearest.push_back(static_cast<float>(cells));
  }
  return std::clamp(static_cast<int>(std::lround(medianOf(nearest))), 1, kReach + 1);
}

}  // namespace mlmap
