// Internal to the point labels: where each level patch's blocks lie within a reach of
// cells, for the search of a floor at a box side's foot far from the scanner, where the
// floor's scan lines lie many cells apart (point_labels.cpp). Looking at every cell round
// such a point cost more than the rest of the labelling (3DTK's scans at 5 cm: 625 cells
// for each point by a wall's foot or top); a bitmap per level patch, dilated once, answers
// it with one bit per level patch.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "mlmap/map/ml_map.hpp"

namespace mlmap {

class LevelCover {
 public:
  // `slot_of(block.plane)`: the patch slot of a block's plane (0: none); `level[slot]`:
  // whether the patch is level. `reach`: cells (Chebyshev) round a block that it covers.
  LevelCover(const MLMap& map, const std::function<std::uint32_t(std::int32_t)>& slot_of,
             const std::vector<bool>& level, std::int32_t reach);

  // Calls visit(slot) for every level slot with a block within the reach of `cell`.
  template <typename Visit>
  void forEachNear(const CellIndex& cell, Visit&& visit) const {
    for (const Cover& cover : covers_) {
      const std::int64_t i = static_cast<std::int64_t>(cell.i) - cover.i0;
      const std::int64_t j = static_cast<std::int64_t>(cell.j) - cover.j0;
      if (i < 0 || j < 0 || i >= cover.rows || j >= cover.columns) continue;
      if (cover.bits[static_cast<std::size_t>(i * cover.columns + j)] != 0) visit(cover.slot);
    }
  }

 private:
  struct Cover {
    std::uint32_t slot = 0;
    std::int64_t i0 = 0, j0 = 0;         // the box's first row and column
    std::int64_t rows = 0, columns = 0;  // its size, the reach round the blocks included
    std::vector<std::uint8_t> bits;      // row by row: 1 where a block lies within the reach
  };
  std::vector<Cover> covers_;
};

}  // namespace mlmap
