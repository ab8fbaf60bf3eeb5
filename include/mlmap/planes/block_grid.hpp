// The blocks of an ML map as eRMSM sees them (section V): each block a point for
// distances, its surface in surface units, its cell; and a dense grid over the
// map's cells for neighbourhood queries in Chebyshev radius r.
//
// In cells finer than the gaps a scanner leaves on a surface, one surface section is
// several map blocks: a wall's cell column at 2 cm holds a stack of short blocks
// between the scan lines, and a floor cell two blocks either side of the range
// noise (a point more than a cell from a block starts a new one, section IV). eRMSM
// sees such a stack as one block: consecutive blocks of a cell closer than
// `stack_gap` join, and the joined block is vertical only when it is deeper than
// `level_band` (else it is level, at the inverse-variance mean of its members'
// heights). The map itself is not changed; each eRMSM block names its map blocks.
//
// Blocks are numbered row by row over the grid (cells ascending in i, then j), not in
// the map's cell order (the order the scans created them): neighbours in a Chebyshev
// window are then a few runs of consecutive ids, and every per-block pass of eRMSM
// streams through memory instead of jumping across it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "mlmap/map/ml_map.hpp"

namespace mlmap {

struct PlaneBlock {
  // m: where its points are across (their mean x, y; the cell centre for a map without
  // point moments) at h (horizontal) or mid-height (vertical)
  Eigen::Vector3f point;
  float offset_x = 0.0F;  // cells: point x, y from the cell centre, within ±0.5
  float offset_y = 0.0F;
  float top = 0.0F;       // m, h
  float bottom = 0.0F;    // m, h − d
  float surface = 1.0F;   // surface units: 1 (horizontal) or d / cell_size (vertical)
  bool vertical = false;  // deeper than the level band (shallower stacks count as horizontal)
  CellIndex cell;
  std::uint16_t map_first = 0;  // its map blocks: [map_first, map_first + map_count) of the cell's list
  std::uint16_t map_count = 1;
};

struct BlockGridConfig {
  double stack_gap = 0.0;   // m, consecutive blocks of a cell closer than this are one eRMSM block
  double level_band = 0.0;  // m, a block (or stack) no deeper than this is level; at least the cell size
  // A surface seen at a grazing angle, or far away, is sampled by scan lines further
  // apart than the stack gap: its cell column holds a ladder of short blocks. A run of
  // at least `ladder_blocks` blocks, each shorter than `ladder_gap` and less than
  // `ladder_gap` apart, is one block too (two or three blocks that far apart are
  // more likely separate objects, a shelf, a seat).
  double ladder_gap = 0.0;  // m; 0 = no ladders
  int ladder_blocks = 4;
  double rung_variance = 0.0;  // m², a level rung's variance exceeds this (fused from few points)
};

class BlockGrid {
 public:
  explicit BlockGrid(const MLMap& map, const BlockGridConfig& config = {});

  double cellSize() const { return cell_size_; }
  const std::vector<PlaneBlock>& blocks() const { return blocks_; }
  std::size_t size() const { return blocks_.size(); }

  // The grid's cells are numbered row by row (the map's cells, in another order): block
  // ids of cell number n are [firstBlockOfCell(n), firstBlockOfCell(n + 1)), and each
  // names its map blocks in the map's cell number mapCellOf(n) (PlaneBlock::map_first, map_count).
  std::uint32_t firstBlockOfCell(std::size_t cell_number) const { return cell_first_[cell_number]; }
  std::size_t mapCellOf(std::size_t cell_number) const { return map_cell_[cell_number]; }
  std::size_t cellCount() const { return map_cell_.size(); }
  // Block ids in the map's own cell order (the order its scans created the cells), each
  // cell bottom to top: eRMSM draws its seeds from a list in this order, so its random
  // draws do not depend on how the grid numbers the blocks. With `keep` (a flag per
  // block id), only the flagged ones. `threads` > 1: chunks of the map's cells on that
  // many OpenMP threads (the order visits the grid at random, a cache miss per cell).
  std::vector<std::uint32_t> idsInMapOrder(std::span<const std::uint8_t> keep = {}, int threads = 1) const;

  // The moments of the points of block `id`'s map blocks, x and y from its cell's
  // centre (cellCentre); empty for a map without point moments. The map the grid was
  // made from must still be alive.
  PointStats pointsOf(std::uint32_t id) const;
  // Where cell `cell`'s centre is in the grid's frame: the map's, moved by origin() where
  // the map lies far from its own origin (see there).
  Eigen::Vector2d cellCentre(CellIndex cell) const {
    return {(static_cast<double>(std::int64_t{cell.j} - origin_j_) + 0.5) * cell_size_,
            (static_cast<double>(std::int64_t{cell.i} - origin_i_) + 0.5) * cell_size_};
  }
  // Where the grid's frame (block points, cellCentre, pointsFrameOf, and the planes found
  // on them) has its origin in the map's: zero, or a cell corner amid the map where its
  // cells lie so far out that float coordinates, which the blocks' points are kept in,
  // would round by more than a thousandth of a cell (a cloud in a national grid, x 500 km and
  // y 5,000 km: rounded to 3 and 50 cm). Planes found on the grid move back by it.
  Eigen::Vector3d origin() const {
    return {static_cast<double>(origin_j_) * cell_size_, static_cast<double>(origin_i_) * cell_size_, 0.0};
  }
  // The cell's index counted from the cell at origin(): the map grid's raster of a level
  // plane (raster_frame.hpp) is in these.
  CellIndex localCell(CellIndex cell) const {
    return {static_cast<std::int32_t>(cell.i - origin_i_), static_cast<std::int32_t>(cell.j - origin_j_)};
  }
  // The frame pointsOf(id) is in: block `id`'s cell centre at z 0 (its points' mean is
  // this plus PointStats::mean()).
  Eigen::Vector3d pointsFrameOf(std::uint32_t id) const {
    const Eigen::Vector2d centre = cellCentre(blocks_[id].cell);
    return {centre.x(), centre.y(), 0.0};
  }

  // Calls visit(block_id) for every block in cells within Chebyshev radius `radius` of
  // `cell`, row by row and in each cell bottom to top: ids ascending.
  template <typename Visit>
  void forEachNeighbour(CellIndex cell, int radius, Visit&& visit) const {
    forEachInCells(std::int64_t{cell.i} - radius, std::int64_t{cell.i} + radius, std::int64_t{cell.j} - radius,
                   std::int64_t{cell.j} + radius, visit);
  }

  // The same for every block in cells i_low ≤ i ≤ i_high, j_low ≤ j ≤ j_high.
  template <typename Visit>
  void forEachInCells(std::int64_t i_low, std::int64_t i_high, std::int64_t j_low, std::int64_t j_high,
                      Visit&& visit) const {
    const std::int64_t row_begin = std::max<std::int64_t>(i_low - min_i_, 0);
    const std::int64_t row_end = std::min<std::int64_t>(i_high - min_i_, rows_ - 1);
    const std::int64_t column_begin = std::max<std::int64_t>(j_low - min_j_, 0);
    const std::int64_t column_end = std::min<std::int64_t>(j_high - min_j_, columns_ - 1);
    // Columns wholly beside the grid: its rows' entries there belong to other rows.
    if (column_begin > column_end) return;
    for (std::int64_t row = row_begin; row <= row_end; ++row) {
      // The row's cells in the window hold one run of consecutive ids.
      const std::uint32_t* line = first_id_from_.data() + row * columns_;
      const std::uint32_t end = line[column_end + 1];
      for (std::uint32_t id = line[column_begin]; id < end; ++id) visit(id);
    }
  }

 private:
  double cell_size_;
  const MLMap* map_;
  std::vector<PlaneBlock> blocks_;
  std::vector<std::uint32_t> cell_first_;  // per cell number, plus one past the end
  std::vector<std::uint32_t> map_cell_;    // per cell number: the map's number of that cell
  // Per position of the dense rows × columns grid, and one past the end: the first
  // block id of the first occupied cell at or after it, row by row (the blocks' number
  // when there is none). A row's blocks in columns c0..c1 are the ids from its entry
  // at c0 to its entry at c1 + 1: two lookups, where scanning the window's cells for
  // occupied ones mispredicted on every gap between scan lines.
  std::vector<std::uint32_t> first_id_from_;
  std::int64_t min_i_ = 0;
  std::int64_t min_j_ = 0;
  std::int64_t origin_i_ = 0;  // the cell whose lower corner is origin()
  std::int64_t origin_j_ = 0;
  std::int64_t rows_ = 0;
  std::int64_t columns_ = 0;
};

}  // namespace mlmap
