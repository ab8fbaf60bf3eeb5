// The map's blocks for the web dashboard's blocks layer: a compact binary file,
// "mlmap.blocks/1", enough to draw every block as a box at its cell, height and depth
// and to colour it by plane. Column-wise, so the page reads each column as one typed
// array. Little-endian throughout; N blocks, 24 + 21·N bytes:
//
//   offset        size  what
//   0             8     magic "MLBLOCKS"
//   8             4     uint32 version, 1
//   12            4     uint32 N, the number of blocks
//   16            8     float64 cell size, m
//   24            4·N   int32 j: the cell's column; x of its centre = (j + 0.5) · cell size
//   24 + 4·N      4·N   int32 i: the cell's row;    y of its centre = (i + 0.5) · cell size
//   24 + 8·N      4·N   float32 top, m: h, the surface (horizontal) or the top (vertical)
//   24 + 12·N     4·N   float32 depth, m: d, the extent below the top; 0 for horizontal
//   24 + 16·N     4·N   int32 plane: π, the id of the block's plane (the planes JSON's id), 0 = none
//   24 + 20·N     N     uint8 kind: 0 horizontal, 1 vertical
//
// Blocks in the map's cell order, lowest first within a cell.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "mlmap/map/ml_map.hpp"

namespace mlmap::io {

constexpr std::uint32_t kDashboardBlocksVersion = 1;

struct DashboardBlock {
  CellIndex cell;
  float top = 0.0F;        // m
  float depth = 0.0F;      // m
  std::int32_t plane = 0;  // 0 = none
  BlockKind kind = BlockKind::Horizontal;
};

struct DashboardBlocks {
  double cell_size = 0.0;  // m
  std::vector<DashboardBlock> blocks;
};

// The file's bytes for the map's block layer.
std::string dashboardBlocks(const MLMap& map);

// Reads the bytes back. Input is untrusted: a wrong magic or version, a size that is
// not 24 + 21·N, a cell size that is not a positive finite number, a non-finite height,
// a negative depth or an unknown kind throws mlmap::Error naming `name`.
DashboardBlocks parseDashboardBlocks(std::string_view bytes, const std::string& name);

}  // namespace mlmap::io
