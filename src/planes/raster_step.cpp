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
  const std::size_t stride = std::max<std::size_t>(1, blocks.size() / 1024);
  std::vector<float> nearest;
  nearest.reserve(blocks.size() / stride + 1);
  for (std::size_t k = 0; k < blocks.size(); k += stride) {
    const std::uint32_t id = blocks[k];
    const PlaneBlock& block = grid.blocks()[id];
    double best = (kReach + 1) * cell;
    grid.forEachNeighbour(block.cell, kReach, [&](std::uint32_t other) {
      if (other == id || !std::binary_search(blocks.begin(), blocks.end(), other)) return;
      best = std::min(best, static_cast<double>((grid.blocks()[other].point - block.point).norm()));
    });
    nearest.push_back(static_cast<float>(best / cell));
  }
  return std::clamp(static_cast<int>(std::lround(medianOf(nearest))), 1, kReach + 1);
}

}  // namespace mlmap
