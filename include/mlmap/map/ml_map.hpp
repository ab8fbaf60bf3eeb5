// The Multi-Level map (section IV): a 2D grid of cells, each holding a short list of
// blocks ordered by height. Cells live in a hash grid, so the map has no fixed bounds.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "mlmap/map/block.hpp"
#include "mlmap/scan.hpp"

namespace mlmap {

struct MLMapStats {
  std::size_t cells = 0;
  std::size_t blocks = 0;
  std::size_t horizontal_blocks = 0;
  std::size_t vertical_blocks = 0;
  std::size_t labelled_blocks = 0;  // blocks with a plane label
  std::size_t memory_bytes = 0;     // heap bytes held by the block layer
  Eigen::Vector3d min = Eigen::Vector3d::Zero();  // m, bounds of the cells and blocks
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

class MLMap {
 public:
  explicit MLMap(double cell_size);

  double cellSize() const { return cell_size_; }
  CellIndex cellOf(double x, double y) const;  // throws for coordinates beyond ±2^30 cells or NaN
  std::optional<CellIndex> findCellOf(double x, double y) const;  // the same, without throwing
  Eigen::Vector2d cellCenter(CellIndex cell) const;  // (x, y) of the cell's centre

  // Adds one measurement p (world frame) with variance σ_m by the rules of Fig. 3.
  void insert(const Point& point, double variance);
  // Adds every point of the scan, moved to the world frame by its pose.
  void insertScan(const Scan& scan);
  // Adds a finished block, as a map reader or a merge does, by the same rules: a
  // horizontal block is fused like a measurement, a vertical one joins the blocks it
  // reaches; its points' moments (relative to this cell's centre) join theirs.
  void insertBlock(CellIndex cell, const Block& block);

  // Restores a cell's blocks verbatim (map readers); the cell must be new and the
  // blocks sorted, each at least cell_size above the one below.
  void restoreCell(CellIndex cell, std::span<const Block> blocks);

  // The blocks of a cell, lowest first; empty when the cell has none.
  std::span<const Block> blocks(CellIndex cell) const;
  std::span<Block> mutableBlocks(CellIndex cell);

  // Cells in a stable order (the order they were created), for iteration by number.
  std::size_t cellCount() const { return cells_.size(); }
  CellIndex cellAt(std::size_t cell_number) const { return cells_[cell_number].index; }
  std::span<const Block> blocksAt(std::size_t cell_number) const;
  std::span<Block> mutableBlocksAt(std::size_t cell_number);
  std::optional<std::size_t> cellNumber(CellIndex cell) const;

  std::size_t blockCount() const { return block_count_; }
  MLMapStats stats() const;

  // Releases the slack left by cells that grew; call after building.
  void compact();
  // Room for this many cells and blocks in all, allocated at once (reading a map file,
  // whose header gives both, instead of growing the arena and the grid step by step).
  void reserve(std::size_t cells, std::size_t blocks);
  // stats().memory_bytes of a compacted map of this many (non-empty) cells and blocks,
  // as reading a map file leaves it.
  static std::size_t packedMemoryBytes(std::size_t cells, std::size_t blocks);

 private:
  struct Cell {
    CellIndex index;
    std::uint32_t first = 0;     // into blocks_
    std::uint16_t count = 0;
    std::uint16_t capacity = 0;
  };
  static constexpr std::size_t kMaxBlocksPerCell = UINT16_MAX;  // Cell::count's range

  std::size_t findOrCreateCell(CellIndex cell);
  void reserveCell(Cell& cell, std::size_t capacity);
  void reserveArena(std::size_t extra);  // room for `extra` more blocks at the arena's end
  void insertIntoCell(std::size_t cell_number, float top, float bottom, float variance, const PointStats& points);
  void rehash(std::size_t slot_count);

  double cell_size_;
  double inverse_cell_size_;
  std::vector<Cell> cells_;
  std::vector<Block> blocks_;           // all cells' blocks; each cell owns a run
  std::vector<std::uint32_t> slots_;    // open-addressing hash of cell numbers
  std::size_t block_count_ = 0;
  std::size_t last_cell_ = SIZE_MAX;    // consecutive points of a scan often share a cell
};

}  // namespace mlmap
