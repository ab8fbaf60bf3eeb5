// .mlmap files: a versioned binary format holding a Map's parameters, its blocks and
// its OcTree (OctoMap's own stream inside), closed by a CRC-32 of all that precedes.
//
//   magic      8 bytes  "\x89MLMAP\r\n" (binary-safe, like PNG's)
//   version    u32      kMapFileVersion
//   flags      u32      bit 0: an OcTree follows, bit 1: planes follow (version ≥ 2)
//   cell_size, octree_resolution, max_range   f64 each, metres
//   origin     x y z f64 each, metres (version ≥ 4: MapConfig::origin; 0 before)
//   cell_count u64, block_count u64
//   per cell:  i i32, j i32, n u16, then n blocks: h f32, σ f32, d f32, π i32, kind u8,
//              and from version 3 the points' moments: count u32, mean x y z f32 (x, y
//              from the cell's centre), scatter xx xy xz yy yz zz f32
//   octree     u64 byte count, then OcTree::write() output (.ot stream)
//   planes     u64 byte count, then the planes JSON (mlmap.planes/1) the labels refer to
//   crc32      u32 over every byte before it
// All numbers little-endian.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>

#include "mlmap/io/octree_summary.hpp"
#include "mlmap/map/map.hpp"

namespace mlmap::io {

// 1: no planes section; 2: no point moments per block (both still read, their blocks
// then sit at their cell centres for plane detection); 3: no origin (the world's).
// The planes section holds the planes in the world's coordinates, as `mlmap planes --json`
// writes them; the map keeps them in its own frame.
constexpr std::uint32_t kMapFileVersion = 4;

// Written to a temporary file and renamed: a failure leaves any old file untouched.
void writeMap(const std::filesystem::path& path, const Map& map);

// Throws mlmap::Error naming the file and the byte offset for a damaged file, a file
// of another version, or anything that is not an .mlmap file.
Map readMap(const std::filesystem::path& path);

// For `mlmap info`: the map's parameters and planes, without its blocks and OcTree
// (map.blocks() empty, hasOctree() false); what the OcTree section holds, counted
// without building it (nullopt when the file has none); and the block layer's figures
// as readMap(path).blocks().stats() gives them, counted without restoring the blocks.
struct MapSummary {
  Map map;
  std::optional<OctreeSummary> octree;
  MLMapStats blocks;
};
MapSummary readMapSummary(const std::filesystem::path& path);

}  // namespace mlmap::io
