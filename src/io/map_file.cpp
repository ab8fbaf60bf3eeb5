#include "mlmap/io/map_file.hpp"

#include <bit>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <octomap/AbstractOcTree.h>

#include "captured_cerr.hpp"
#include "crc32.hpp"
#include "file_bytes.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/atomic_file.hpp"
#include "mlmap/io/planes_json.hpp"

namespace mlmap::io {
namespace {

static_assert(std::endian::native == std::endian::little, "the .mlmap codec assumes little-endian");

constexpr char kMagic[8] = {'\x89', 'M', 'L', 'M', 'A', 'P', '\r', '\n'};
constexpr std::uint32_t kHasOctree = 1U;
constexpr std::uint32_t kHasPlanes = 2U;
constexpr std::uint32_t kOldestReadableVersion = 1;
constexpr std::size_t kBlockBytesV2 = 17;
// Version 3 adds the points' moments: count u32, mean f32 × 3, scatter f32 × 6.
constexpr std::size_t kPointStatsBytes = 40;
constexpr std::size_t blockBytes(std::uint32_t version) { return kBlockBytesV2 + (version >= 3 ? kPointStatsBytes : 0); }
constexpr std::size_t kCellHeaderBytes = 10;

template <typename T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

// Reads the file's bytes in order; every read is bounds-checked and an error names
// the file and the byte offset where it happened.
class ByteReader {
 public:
  ByteReader(std::string_view bytes, std::size_t end, std::string name)
      : bytes_(bytes), end_(end), name_(std::move(name)) {}

  template <typename T>
  T get(const char* what) {
    need(sizeof(T), what);
    T value;
    std::memcpy(&value, bytes_.data() + offset_, sizeof(T));
    offset_ += sizeof(T);
    return value;
  }
  void need(std::size_t count, const char* what) const {
    if (count > end_ - offset_) {
      fail(std::string("file ends inside ") + what + " (needs " + std::to_string(count) +
           " bytes, " + std::to_string(end_ - offset_) + " left)");
    }
  }
  std::string_view take(std::size_t count, const char* what) {
    need(count, what);
    std::string_view view(bytes_.data() + offset_, count);
    offset_ += count;
    return view;
  }
  std::size_t offset() const { return offset_; }
  std::size_t remaining() const { return end_ - offset_; }
  [[noreturn]] void fail(const std::string& what) const { failAt(offset_, what); }
  [[noreturn]] void failAt(std::size_t offset, const std::string& what) const {
    throw Error(name_ + ": byte " + std::to_string(offset) + ": " + what);
  }

 private:
  std::string_view bytes_;
  std::size_t end_;
  std::string name_;
  std::size_t offset_ = 0;
};

}  // namespace

void writeMap(const std::filesystem::path& path, const Map& map) {
  const MLMap& blocks = map.blocks();
  const MapConfig& config = map.config();
  std::string out;
  out.reserve(64 + blocks.cellCount() * kCellHeaderBytes + blocks.blockCount() * blockBytes(kMapFileVersion));
  out.append(kMagic, sizeof(kMagic));
  put<std::uint32_t>(out, kMapFileVersion);
  put<std::uint32_t>(out, (map.hasOctree() ? kHasOctree : 0U) | (map.planes() ? kHasPlanes : 0U));
  put<double>(out, config.cell_size);
  put<double>(out, config.octree_resolution);
  put<double>(out, config.max_range);
  for (int axis = 0; axis < 3; ++axis) put<double>(out, config.origin[axis]);
  std::uint64_t non_empty_cells = 0;
  for (std::size_t n = 0; n < blocks.cellCount(); ++n) non_empty_cells += !blocks.blocksAt(n).empty();
  put<std::uint64_t>(out, non_empty_cells);
  put<std::uint64_t>(out, blocks.blockCount());
  for (std::size_t n = 0; n < blocks.cellCount(); ++n) {
    const auto cell_blocks = blocks.blocksAt(n);
    if (cell_blocks.empty()) continue;
    const CellIndex cell = blocks.cellAt(n);
    put<std::int32_t>(out, cell.i);
    put<std::int32_t>(out, cell.j);
    put<std::uint16_t>(out, static_cast<std::uint16_t>(cell_blocks.size()));
    for (const Block& block : cell_blocks) {
      put<float>(out, block.height);
      put<float>(out, block.variance);
      put<float>(out, block.depth);
      put<std::int32_t>(out, block.plane);
      put<std::uint8_t>(out, static_cast<std::uint8_t>(block.kind));
      const PointStats& points = block.points;
      put<std::uint32_t>(out, points.count);
      put<float>(out, points.mean_x);
      put<float>(out, points.mean_y);
      put<float>(out, points.mean_z);
      for (const float value : points.scatter) put<float>(out, value);
    }
  }
  std::string octree_bytes;
  if (map.hasOctree()) {
    std::ostringstream stream;
    const CapturedCerr quiet;
    map.octree().write(stream);
    octree_bytes = std::move(stream).str();
  }
  put<std::uint64_t>(out, octree_bytes.size());
  // The sections are written one after another, the checksum taken across them,
  // instead of appending the OcTree's tens of megabytes to `out` first (a copy into
  // freshly faulted memory).
  std::string tail;
  if (map.planes()) {
    const std::string planes = planesJson(map, *map.planes(), path.filename().string());
    put<std::uint64_t>(tail, planes.size());
    tail += planes;
  }
  std::uint32_t crc = crc32(out.data(), out.size());
  crc = crc32(octree_bytes.data(), octree_bytes.size(), crc);
  crc = crc32(tail.data(), tail.size(), crc);
  put<std::uint32_t>(tail, crc);
  writeAtomically(path, [&](std::ostream& stream) {
    for (const std::string* section : {&out, &octree_bytes, &tail}) {
      stream.write(section->data(), static_cast<std::streamsize>(section->size()));
    }
  });
}

namespace {

// The block layer's figures (MLMap::stats) from one cell's blocks as the file holds
// them, without restoring them.
void countBlocks(MLMapStats& stats, const CellIndex& cell, const std::vector<Block>& blocks, double cell_size) {
  if (blocks.empty()) return;
  if (stats.blocks == 0) {
    stats.min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    stats.max = -stats.min;
  }
  ++stats.cells;
  stats.blocks += blocks.size();
  for (const Block& block : blocks) {
    (block.isVertical() ? stats.vertical_blocks : stats.horizontal_blocks)++;
    if (block.plane != 0) ++stats.labelled_blocks;
    stats.min.z() = std::min<double>(stats.min.z(), block.bottom());
    stats.max.z() = std::max<double>(stats.max.z(), block.height);
  }
  stats.min.x() = std::min(stats.min.x(), cell.j * cell_size);
  stats.min.y() = std::min(stats.min.y(), cell.i * cell_size);
  stats.max.x() = std::max(stats.max.x(), (cell.j + 1) * cell_size);
  stats.max.y() = std::max(stats.max.y(), (cell.i + 1) * cell_size);
}

// Reads the whole file; with `summary`, the OcTree section is only counted into
// summary->octree, the blocks only into summary->blocks (the returned map has neither:
// `mlmap info` on a 40 MB map took 0.4 s restoring them). The summary checks what the
// reader checks of the file's structure and checksum, not each block's values.
Map readMapFile(const std::filesystem::path& path, MapSummary* summary) {
  const MappedFile file(path);
  const std::string_view bytes = file.bytes();
  const std::string name = path.string();
  if (bytes.size() < sizeof(kMagic) || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    throw Error(name + ": byte 0: not an .mlmap file (bad magic number)");
  }
  ByteReader header(bytes, bytes.size(), name);
  header.take(sizeof(kMagic), "the magic number");
  const auto version = header.get<std::uint32_t>("the version");
  if (version < kOldestReadableVersion || version > kMapFileVersion) {
    header.failAt(8, "format version " + std::to_string(version) + ", this mlmap reads versions " +
                         std::to_string(kOldestReadableVersion) + " to " + std::to_string(kMapFileVersion) +
                         (version > kMapFileVersion ? " (a newer mlmap wrote it)" : ""));
  }
  if (bytes.size() < header.offset() + sizeof(std::uint32_t)) {
    header.fail("file too short for a checksum");
  }
  const std::size_t body_end = bytes.size() - sizeof(std::uint32_t);
  std::uint32_t stored_crc;
  std::memcpy(&stored_crc, bytes.data() + body_end, sizeof(stored_crc));
  if (crc32(bytes.data(), body_end) != stored_crc) {
    throw Error(name + ": checksum mismatch: the file is damaged or truncated");
  }

  ByteReader in(bytes, body_end, name);
  in.take(sizeof(kMagic) + sizeof(std::uint32_t), "the header");
  const auto flags = in.get<std::uint32_t>("the flags");
  MapConfig config;
  config.cell_size = in.get<double>("the cell size");
  config.octree_resolution = in.get<double>("the OcTree resolution");
  config.max_range = in.get<double>("the maximum range");
  if (version >= 4) {
    for (int axis = 0; axis < 3; ++axis) config.origin[axis] = in.get<double>("the origin");
    if (!(config.origin.allFinite() && config.origin.cwiseAbs().maxCoeff() < 1e9)) {
      in.failAt(40, "the origin is not a finite point within 10^9 m");
    }
  }
  config.with_octree = (flags & kHasOctree) != 0;
  const bool has_planes = (flags & kHasPlanes) != 0;
  if ((flags & ~(kHasOctree | kHasPlanes)) != 0 || (has_planes && version < 2)) {
    in.failAt(12, "unknown flags " + std::to_string(flags));
  }
  if (!(config.cell_size > 0.0 && config.cell_size < 1e3) ||
      (config.with_octree && !(config.octree_resolution > 0.0 && config.octree_resolution < 1e3))) {
    in.failAt(16, "cell size or OcTree resolution out of range");
  }
  Map map(config);
  const auto cell_count = in.get<std::uint64_t>("the cell count");
  const auto block_count = in.get<std::uint64_t>("the block count");
  // Refuse counts the file cannot hold before allocating anything for them.
  if (cell_count > in.remaining() / kCellHeaderBytes ||
      block_count > in.remaining() / blockBytes(version)) {
    in.fail("the header claims " + std::to_string(cell_count) + " cells and " +
            std::to_string(block_count) + " blocks, more than the file holds");
  }
  if (summary == nullptr) map.blocks().reserve(cell_count, block_count);
  std::vector<Block> cell_blocks;
  std::uint64_t blocks_seen = 0;
  for (std::uint64_t c = 0; c < cell_count; ++c) {
    const std::size_t cell_offset = in.offset();
    const CellIndex cell{in.get<std::int32_t>("a cell index"), in.get<std::int32_t>("a cell index")};
    const auto count = in.get<std::uint16_t>("a block count");
    in.need(std::size_t{count} * blockBytes(version), "a cell's blocks");
    cell_blocks.resize(count);
    for (Block& block : cell_blocks) {
      block.height = in.get<float>("a block");
      block.variance = in.get<float>("a block");
      block.depth = in.get<float>("a block");
      block.plane = in.get<std::int32_t>("a block");
      const auto kind = in.get<std::uint8_t>("a block");
      if (kind > 1) in.failAt(in.offset() - 1, "unknown block kind " + std::to_string(kind));
      block.kind = static_cast<BlockKind>(kind);
      block.points = PointStats{};
      if (version >= 3) {
        block.points.count = in.get<std::uint32_t>("a block's points");
        block.points.mean_x = in.get<float>("a block's points");
        block.points.mean_y = in.get<float>("a block's points");
        block.points.mean_z = in.get<float>("a block's points");
        for (float& value : block.points.scatter) value = in.get<float>("a block's points");
      }
    }
    blocks_seen += count;
    if (summary != nullptr) {
      countBlocks(summary->blocks, cell, cell_blocks, config.cell_size);
      continue;
    }
    try {
      map.blocks().restoreCell(cell, cell_blocks);
    } catch (const Error& error) {
      in.failAt(cell_offset, error.what());
    }
  }
  if (blocks_seen != block_count) {
    in.fail("the header claims " + std::to_string(block_count) + " blocks, the cells hold " +
            std::to_string(blocks_seen));
  }
  const auto octree_size = in.get<std::uint64_t>("the OcTree size");
  if (has_planes ? octree_size > in.remaining() : octree_size != in.remaining()) {
    in.fail("the OcTree claims " + std::to_string(octree_size) + " bytes, " +
            std::to_string(in.remaining()) + " remain");
  }
  if (config.with_octree && summary != nullptr) {
    const std::size_t octree_offset = in.offset();
    try {
      summary->octree = summarizeOctree(in.take(octree_size, "the OcTree"));
    } catch (const Error& error) {
      in.failAt(octree_offset, error.what());
    }
    map.setOctree(nullptr);
  } else if (config.with_octree) {
    const std::size_t octree_offset = in.offset();
    std::istringstream stream(std::string(in.take(octree_size, "the OcTree")));
    CapturedCerr octomap_says;
    std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(stream));
    auto* octree = dynamic_cast<octomap::OcTree*>(tree.get());
    if (octree == nullptr) {
      in.failAt(octree_offset, "the embedded OcTree cannot be read (" + octomap_says.text() + ")");
    }
    tree.release();
    try {
      map.setOctree(std::unique_ptr<octomap::OcTree>(octree));
    } catch (const Error& error) {
      in.failAt(octree_offset, error.what());
    }
  } else if (octree_size != 0) {
    in.fail("an OcTree follows but the flags say none");
  }
  if (has_planes) {
    const auto planes_size = in.get<std::uint64_t>("the planes size");
    if (planes_size != in.remaining()) {
      in.fail("the planes claim " + std::to_string(planes_size) + " bytes, " + std::to_string(in.remaining()) +
              " remain");
    }
    const std::size_t planes_offset = in.offset();
    try {
      PlaneDetection planes = parsePlanesJson(in.take(planes_size, "the planes"), "the planes");
      // Written in the world's coordinates (planesJson), kept in the map's frame.
      if (!config.origin.isZero())
        for (Plane& plane : planes.planes) movePlane(plane, -config.origin);
      map.setPlanes(std::move(planes));
    } catch (const Error& error) {
      in.failAt(planes_offset, error.what());
    }
  }
  map.blocks().compact();
  return map;
}

}  // namespace

Map readMap(const std::filesystem::path& path) { return readMapFile(path, nullptr); }

MapSummary readMapSummary(const std::filesystem::path& path) {
  MapSummary summary{Map(MapConfig{}), std::nullopt, MLMapStats{}};
  summary.map = readMapFile(path, &summary);
  summary.blocks.memory_bytes = MLMap::packedMemoryBytes(summary.blocks.cells, summary.blocks.blocks);
  return summary;
}

}  // namespace mlmap::io
