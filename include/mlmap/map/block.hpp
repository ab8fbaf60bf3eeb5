// A block of the ML map (section IV): a section of an object's surface above one
// cell. Horizontal blocks are floor, ceiling or table sections (depth 0); vertical
// blocks are wall sections spanning [height − depth, height].
#pragma once

#include <cstdint>

#include "mlmap/map/point_stats.hpp"

namespace mlmap {

enum class BlockKind : std::uint8_t { Horizontal = 0, Vertical = 1 };

struct Block {
  float height = 0.0F;     // m, h: the surface height (horizontal) or the top (vertical)
  float variance = 0.0F;   // m², σ: of h (Kalman for horizontal, the top measurement's for vertical)
  float depth = 0.0F;      // m, d: the vertical extent below h; 0 for horizontal blocks
  std::int32_t plane = 0;  // π: label of the matching plane, 0 = none
  BlockKind kind = BlockKind::Horizontal;
  // Beyond the paper's (h, σ, d, π): the moments of the points the block collected
  // (empty for maps written before format version 3).
  PointStats points;

  float bottom() const { return height - depth; }
  bool isVertical() const { return kind == BlockKind::Vertical; }
};

// A cell c_ij of the grid: j = floor(x / cell_size), i = floor(y / cell_size).
struct CellIndex {
  std::int32_t i = 0;  // row, along y
  std::int32_t j = 0;  // column, along x
  friend bool operator==(const CellIndex&, const CellIndex&) = default;
};

}  // namespace mlmap
