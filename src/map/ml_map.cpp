// The ML map's storage: cells in an open-addressing hash grid, each owning a run of
// blocks in one arena. The update rules themselves live in block_rules.cpp, a scan's
// batch insertion in ml_map_scan.cpp.
#include "mlmap/map/ml_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "block_rules.hpp"
#include "mlmap/error.hpp"

namespace mlmap {
namespace {

constexpr std::uint32_t kEmptySlot = std::numeric_limits<std::uint32_t>::max();
constexpr std::size_t kInitialSlots = 1024;  // the cell grid's hash table, a power of two

std::uint64_t packCell(CellIndex cell) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(cell.i)) << 32) |
         static_cast<std::uint32_t>(cell.j);
}

std::size_t slotFor(CellIndex cell, std::size_t mask) {
  // Fibonacci hashing spreads neighbouring cells over the table.
  return static_cast<std::size_t>((packCell(cell) * 0x9E3779B97F4A7C15ULL) >> 20) & mask;
}

// A block's point moments as a reader may restore them: finite, the mean's x and y
// near the cell (a merged map's blocks may sit up to a cell beside their own), the
// scatter's diagonal not negative beyond rounding.
bool validStats(const PointStats& stats, double cell_size) {
  if (stats.count == 0) return true;
  const auto reach = static_cast<float>(cell_size);
  bool finite = std::isfinite(stats.mean_z) && std::abs(stats.mean_x) <= reach && std::abs(stats.mean_y) <= reach;
  for (const float value : stats.scatter) finite = finite && std::isfinite(value) && std::abs(value) < 1e12F;
  return finite && stats.scatter[0] >= -1e-6F && stats.scatter[3] >= -1e-6F && stats.scatter[5] >= -1e-6F;
}

}  // namespace

MLMap::MLMap(double cell_size) : cell_size_(cell_size), inverse_cell_size_(1.0 / cell_size) {
  if (!(cell_size > 0.0) || !std::isfinite(cell_size)) {
    throw Error("cell size must be a positive number of metres, got " + std::to_string(cell_size));
  }
  slots_.assign(kInitialSlots, kEmptySlot);
}

std::optional<CellIndex> MLMap::findCellOf(double x, double y) const {
  const double column = std::floor(x * inverse_cell_size_);
  const double row = std::floor(y * inverse_cell_size_);
  constexpr double kLimit = 1 << 30;
  if (!(std::abs(column) < kLimit && std::abs(row) < kLimit)) return std::nullopt;
  return CellIndex{static_cast<std::int32_t>(row), static_cast<std::int32_t>(column)};
}

CellIndex MLMap::cellOf(double x, double y) const {
  const auto cell = findCellOf(x, y);
  if (!cell) {
    throw Error("point (" + std::to_string(x) + ", " + std::to_string(y) +
                ") is outside the map's range or not finite");
  }
  return *cell;
}

Eigen::Vector2d MLMap::cellCenter(CellIndex cell) const {
  return {(cell.j + 0.5) * cell_size_, (cell.i + 0.5) * cell_size_};
}

std::optional<std::size_t> MLMap::cellNumber(CellIndex cell) const {
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t slot = slotFor(cell, mask);; slot = (slot + 1) & mask) {
    const std::uint32_t number = slots_[slot];
    if (number == kEmptySlot) return std::nullopt;
    if (cells_[number].index == cell) return number;
  }
}

void MLMap::rehash(std::size_t slot_count) {
  slots_.assign(slot_count, kEmptySlot);
  const std::size_t mask = slot_count - 1;
  for (std::size_t number = 0; number < cells_.size(); ++number) {
    std::size_t slot = slotFor(cells_[number].index, mask);
    while (slots_[slot] != kEmptySlot) slot = (slot + 1) & mask;
    slots_[slot] = static_cast<std::uint32_t>(number);
  }
}

std::size_t MLMap::findOrCreateCell(CellIndex cell) {
  if (last_cell_ < cells_.size() && cells_[last_cell_].index == cell) return last_cell_;
  const std::size_t mask = slots_.size() - 1;
  std::size_t slot = slotFor(cell, mask);
  for (;; slot = (slot + 1) & mask) {
    const std::uint32_t number = slots_[slot];
    if (number == kEmptySlot) break;
    if (cells_[number].index == cell) return last_cell_ = number;
  }
  if (cells_.size() >= kEmptySlot - 1) throw Error("map is full: too many cells");
  cells_.push_back(Cell{cell, static_cast<std::uint32_t>(blocks_.size()), 0, 0});
  slots_[slot] = static_cast<std::uint32_t>(cells_.size() - 1);
  // Keep the load under one half so probes stay short.
  if (cells_.size() * 2 > slots_.size()) rehash(slots_.size() * 2);
  return last_cell_ = cells_.size() - 1;
}

void MLMap::reserveArena(std::size_t extra) {
  // Geometric, as the vector's own growth: reserve() alone takes exactly what is asked.
  if (blocks_.size() + extra > blocks_.capacity()) blocks_.reserve(std::max(blocks_.size() + extra, 2 * blocks_.capacity()));
}

void MLMap::reserveCell(Cell& cell, std::size_t capacity) {
  if (capacity <= cell.capacity) return;
  if (capacity > kMaxBlocksPerCell) throw Error("a cell holds too many blocks");
  if (cell.first + cell.capacity == blocks_.size()) {
    // The cell's run is at the end of the arena: grow it in place.
    blocks_.resize(cell.first + capacity);
  } else {
    const std::size_t first = blocks_.size();
    blocks_.resize(first + capacity);
    std::copy_n(blocks_.begin() + cell.first, cell.count, blocks_.begin() + static_cast<long>(first));
    cell.first = static_cast<std::uint32_t>(first);
  }
  if (blocks_.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw Error("map is full: too many blocks");
  }
  cell.capacity = static_cast<std::uint16_t>(capacity);
}

void MLMap::insertIntoCell(std::size_t cell_number, float top, float bottom, float variance, const PointStats& points) {
  Cell& cell = cells_[cell_number];
  if (cell.count == cell.capacity) {
    reserveCell(cell, std::min<std::size_t>(cell.capacity * 2U + 1U, kMaxBlocksPerCell));
  }
  const int count = addMeasurement(blocks_.data() + cell.first, cell.count, top, bottom, variance,
                                   static_cast<float>(cell_size_), points);
  block_count_ += static_cast<std::size_t>(count) - cell.count;
  cell.count = static_cast<std::uint16_t>(count);
}

void MLMap::insert(const Point& point, double variance) {
  if (!std::isfinite(point.z()) || !(variance > 0.0) || !std::isfinite(variance)) {
    throw Error("measurement with a non-finite height or a non-positive variance");
  }
  const CellIndex cell = cellOf(point.x(), point.y());
  const std::size_t cell_number = findOrCreateCell(cell);
  const auto z = static_cast<float>(point.z());
  const Eigen::Vector2d centre = cellCenter(cell);
  PointStats stats;
  stats.add(static_cast<float>(point.x() - centre.x()), static_cast<float>(point.y() - centre.y()), z);
  insertIntoCell(cell_number, z, z, static_cast<float>(variance), stats);
}

void MLMap::insertBlock(CellIndex cell_index, const Block& block) {
  if (!std::isfinite(block.height) || !std::isfinite(block.depth) || block.depth < 0.0F ||
      !(block.variance > 0.0F) || !std::isfinite(block.variance)) {
    throw Error("block with a non-finite height, a negative depth or a non-positive variance");
  }
  // A block stands for its measurements: a horizontal one is fused like a point of
  // its variance, a vertical one joins every block its extent reaches.
  const float bottom = block.isVertical() ? block.bottom() : block.height;
  insertIntoCell(findOrCreateCell(cell_index), block.height, bottom, block.variance, block.points);
}

void MLMap::restoreCell(CellIndex cell_index, std::span<const Block> blocks) {
  if (cellNumber(cell_index)) {
    throw Error("cell (" + std::to_string(cell_index.i) + ", " + std::to_string(cell_index.j) +
                ") appears twice");
  }
  if (blocks.size() > kMaxBlocksPerCell) throw Error("a cell holds too many blocks");
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const Block& block = blocks[k];
    const bool valid = std::isfinite(block.height) && std::isfinite(block.depth) &&
                       std::isfinite(block.variance) && block.variance > 0.0F &&
                       block.depth >= 0.0F &&
                       (block.isVertical() || block.depth == 0.0F) &&
                       (block.kind == BlockKind::Horizontal || block.kind == BlockKind::Vertical) &&
                       validStats(block.points, cell_size_);
    // Gaps are compared with a float tolerance: the heights were rounded to float after the
    // gap was decided, each by up to half a unit in the last place, which far from z = 0 is
    // more than a part in 10^4 of a cell (at z 300 m 3e-5 m: a map of a cloud in a national
    // grid's heights was written and then refused as out of order).
    const auto ordered = [&] {
      if (k == 0) return true;
      const float lower = blocks[k - 1].height;
      const float upper = block.bottom();
      const float rounding = 2.0F * std::numeric_limits<float>::epsilon() * std::max(std::abs(lower), std::abs(upper));
      return upper - lower >= static_cast<float>(cell_size_ * (1 - 1e-4)) - rounding;
    }();
    if (!valid || !ordered) {
      throw Error("cell (" + std::to_string(cell_index.i) + ", " + std::to_string(cell_index.j) +
                  ") block " + std::to_string(k) + " is invalid or out of order");
    }
  }
  const std::size_t number = findOrCreateCell(cell_index);
  Cell& cell = cells_[number];
  reserveCell(cell, blocks.size());
  std::copy(blocks.begin(), blocks.end(), blocks_.begin() + cell.first);
  cell.count = static_cast<std::uint16_t>(blocks.size());
  block_count_ += blocks.size();
}

std::span<const Block> MLMap::blocksAt(std::size_t cell_number) const {
  const Cell& cell = cells_[cell_number];
  return {blocks_.data() + cell.first, cell.count};
}

std::span<Block> MLMap::mutableBlocksAt(std::size_t cell_number) {
  const Cell& cell = cells_[cell_number];
  return {blocks_.data() + cell.first, cell.count};
}

std::span<const Block> MLMap::blocks(CellIndex cell) const {
  const auto number = cellNumber(cell);
  if (!number) return {};
  return blocksAt(*number);
}

std::span<Block> MLMap::mutableBlocks(CellIndex cell) {
  const auto number = cellNumber(cell);
  if (!number) return {};
  return mutableBlocksAt(*number);
}

MLMapStats MLMap::stats() const {
  MLMapStats stats;
  stats.cells = cells_.size();
  stats.blocks = block_count_;
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const Cell& cell : cells_) {
    for (const Block& block : blocksAt(static_cast<std::size_t>(&cell - cells_.data()))) {
      (block.isVertical() ? stats.vertical_blocks : stats.horizontal_blocks)++;
      if (block.plane != 0) ++stats.labelled_blocks;
      low.z() = std::min<double>(low.z(), block.bottom());
      high.z() = std::max<double>(high.z(), block.height);
    }
    if (cell.count == 0) continue;
    low.x() = std::min(low.x(), cell.index.j * cell_size_);
    low.y() = std::min(low.y(), cell.index.i * cell_size_);
    high.x() = std::max(high.x(), (cell.index.j + 1) * cell_size_);
    high.y() = std::max(high.y(), (cell.index.i + 1) * cell_size_);
  }
  if (block_count_ > 0) {
    stats.min = low;
    stats.max = high;
  }
  stats.memory_bytes = cells_.capacity() * sizeof(Cell) + blocks_.capacity() * sizeof(Block) +
                       slots_.capacity() * sizeof(std::uint32_t) + sizeof(*this);
  return stats;
}

std::size_t MLMap::packedMemoryBytes(std::size_t cells, std::size_t blocks) {
  std::size_t slots = kInitialSlots;
  while (cells * 2 > slots) slots *= 2;
  return cells * sizeof(Cell) + blocks * sizeof(Block) + slots * sizeof(std::uint32_t) + sizeof(MLMap);
}

void MLMap::reserve(std::size_t cells, std::size_t blocks) {
  cells_.reserve(cells);
  blocks_.reserve(blocks);
  std::size_t slots = slots_.size();  // the size findOrCreateCell's growth would reach
  while (cells * 2 > slots) slots *= 2;
  if (slots != slots_.size()) rehash(slots);
}

void MLMap::compact() {
  if (blocks_.size() == block_count_) {
    // No slack (every cell's room holds exactly its blocks, none left behind by a move):
    // packed already, as a restored map is.
    blocks_.shrink_to_fit();
    cells_.shrink_to_fit();
    return;
  }
  std::vector<Block> packed;
  packed.reserve(block_count_);
  for (Cell& cell : cells_) {
    const std::size_t first = packed.size();
    packed.insert(packed.end(), blocks_.begin() + cell.first,
                  blocks_.begin() + cell.first + cell.count);
    cell.first = static_cast<std::uint32_t>(first);
    cell.capacity = cell.count;
  }
  blocks_ = std::move(packed);
  cells_.shrink_to_fit();
}

}  // namespace mlmap
