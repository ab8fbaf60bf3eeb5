#include "mlmap/planes/block_grid.hpp"

#include <algorithm>
#include <cstdlib>
#include <limits>

#include "fill_vector.hpp"
#include "mlmap/error.hpp"

namespace mlmap {
namespace {

// How a cell's blocks join (BlockGridConfig, in the blocks' float heights).
struct StackRule {
  float stack_gap;
  float level_band;
  float ladder_gap;
  std::size_t ladder_blocks;
  float rung_variance;
};

// One cell's blocks as eRMSM blocks: consecutive blocks closer than the stack gap,
// or ladders of short blocks, join (see the header).
void appendStacks(std::span<const Block> cell_blocks, CellIndex cell, const Eigen::Vector2d& centre, double cell_size,
                  const StackRule& rule, std::vector<PlaneBlock>& out) {
  const float stack_gap = rule.stack_gap;
  const float level_band = rule.level_band;
  // A rung is a sliver of one or two scan lines: short, and if level, fused from a
  // few points only (a table top or a seat is fused from many: not a rung).
  const auto rung = [&](std::size_t k) {
    const Block& block = cell_blocks[k];
    return block.depth < rule.ladder_gap && (block.isVertical() || block.variance > rule.rung_variance);
  };
  for (std::size_t first = 0; first < cell_blocks.size();) {
    // The stack: this block and the ones above it closer than the stack gap, or a
    // ladder of rungs, then whatever lies closer than the stack gap above it.
    std::size_t last = first;
    float top = cell_blocks[first].height;
    if (rung(first)) {
      std::size_t ladder_last = first;
      float ladder_top = top;
      while (ladder_last + 1 < cell_blocks.size() && rung(ladder_last + 1) &&
             cell_blocks[ladder_last + 1].bottom() - ladder_top < rule.ladder_gap) {
        ++ladder_last;
        ladder_top = std::max(ladder_top, cell_blocks[ladder_last].height);
      }
      if (ladder_last + 1 - first >= rule.ladder_blocks) {
        last = ladder_last;
        top = ladder_top;
      }
    }
    while (last + 1 < cell_blocks.size() && cell_blocks[last + 1].bottom() - top < stack_gap) {
      ++last;
      top = std::max(top, cell_blocks[last].height);
    }
    PlaneBlock view;
    view.top = top;
    view.bottom = cell_blocks[first].bottom();
    view.map_first = static_cast<std::uint16_t>(first);
    view.map_count = static_cast<std::uint16_t>(last - first + 1);
    // A stack shallower than the level band is the edge of a horizontal surface (a
    // table top with its rim, a stair tread with the top of its riser) or a level
    // surface split by range noise far more often than a wall: eRMSM treats it as
    // horizontal, at its top when it is one vertical block, else at the members'
    // inverse-variance mean height.
    view.vertical = view.top - view.bottom >= level_band;
    view.surface = view.vertical ? static_cast<float>((view.top - view.bottom) / cell_size) : 1.0F;
    float level = view.top;
    if (!view.vertical && last > first) {
      double weighted = 0.0;
      double weight = 0.0;
      for (std::size_t k = first; k <= last; ++k) {
        const double w = 1.0 / std::max(cell_blocks[k].variance, 1e-12F);
        weighted += w * cell_blocks[k].height;
        weight += w;
      }
      level = static_cast<float>(weighted / weight);
    }
    // Across, the block is where its points are: a wall turned to the grid, or on a
    // cell boundary, stays a straight line of blocks (see point_stats.hpp). A merged
    // map's block may hold points from just beside its cell: kept within the cell.
    PointStats points;
    for (std::size_t k = first; k <= last; ++k) points.merge(cell_blocks[k].points);
    if (!points.empty()) {
      view.offset_x = std::clamp(static_cast<float>(points.mean_x / cell_size), -0.5F, 0.5F);
      view.offset_y = std::clamp(static_cast<float>(points.mean_y / cell_size), -0.5F, 0.5F);
    }
    view.point = Eigen::Vector3f(static_cast<float>(centre.x() + view.offset_x * cell_size),
                                 static_cast<float>(centre.y() + view.offset_y * cell_size),
                                 view.vertical ? 0.5F * (view.top + view.bottom) : level);
    view.cell = cell;
    out.push_back(view);
    first = last + 1;
  }
}

}  // namespace

BlockGrid::BlockGrid(const MLMap& map, const BlockGridConfig& config) : cell_size_(map.cellSize()), map_(&map) {
  const StackRule rule{static_cast<float>(config.stack_gap),
                       static_cast<float>(std::max(config.level_band, cell_size_)),
                       static_cast<float>(config.ladder_gap),
                       static_cast<std::size_t>(std::max(config.ladder_blocks, 2)),
                       static_cast<float>(config.rung_variance)};
  const std::size_t cell_count = map.cellCount();
  cell_first_.assign(1, 0);
  if (cell_count == 0) return;
  min_i_ = std::numeric_limits<std::int64_t>::max();
  min_j_ = std::numeric_limits<std::int64_t>::max();
  std::int64_t max_i = std::numeric_limits<std::int64_t>::min();
  std::int64_t max_j = std::numeric_limits<std::int64_t>::min();
  for (std::size_t n = 0; n < cell_count; ++n) {
    const CellIndex cell = map.cellAt(n);
    min_i_ = std::min<std::int64_t>(min_i_, cell.i);
    min_j_ = std::min<std::int64_t>(min_j_, cell.j);
    max_i = std::max<std::int64_t>(max_i, cell.i);
    max_j = std::max<std::int64_t>(max_j, cell.j);
  }
  rows_ = max_i - min_i_ + 1;
  columns_ = max_j - min_j_ + 1;
  // Float keeps 24 bits: past 2^13 cells from the origin its unit in the last place is over
  // a thousandth of a cell (0.05 m cells: 410 m out). Maps that near keep the map's frame
  // (their planes to the bit as before); farther ones are centred.
  constexpr std::int64_t kFloatSafeCells = std::int64_t{1} << 13;
  const std::int64_t farthest = std::max({std::abs(min_i_), std::abs(max_i + 1), std::abs(min_j_), std::abs(max_j + 1)});
  if (farthest > kFloatSafeCells) {
    origin_i_ = min_i_ + (max_i - min_i_) / 2;
    origin_j_ = min_j_ + (max_j - min_j_) / 2;
  }
  // A building at a few centimetres fits easily; a map spread over kilometres does not.
  constexpr std::int64_t kMaxGridCells = std::int64_t{1} << 28;
  if (rows_ > kMaxGridCells / columns_) {
    throw Error("map too sparse for plane detection: " + std::to_string(rows_) + " × " +
                std::to_string(columns_) + " cells in its bounding box");
  }
  // The map's cell numbers on the grid first, then renumbered row by row.
  std::vector<std::int32_t> grid(static_cast<std::size_t>(rows_ * columns_), -1);
  for (std::size_t n = 0; n < cell_count; ++n) {
    const CellIndex cell = map.cellAt(n);
    grid[static_cast<std::size_t>((cell.i - min_i_) * columns_ + (cell.j - min_j_))] = static_cast<std::int32_t>(n);
  }
  blocks_.reserve(map.blockCount());
  cell_first_.reserve(cell_count + 1);
  map_cell_.reserve(cell_count);
  first_id_from_.resize(grid.size() + 1);
  for (std::size_t position = 0; position < grid.size(); ++position) {
    first_id_from_[position] = static_cast<std::uint32_t>(blocks_.size());
    if (grid[position] < 0) continue;
    const auto map_cell = static_cast<std::size_t>(grid[position]);
    map_cell_.push_back(static_cast<std::uint32_t>(map_cell));
    const CellIndex cell = map.cellAt(map_cell);
    appendStacks(map.blocksAt(map_cell), cell, cellCentre(cell), cell_size_, rule, blocks_);
    cell_first_.push_back(static_cast<std::uint32_t>(blocks_.size()));
  }
  first_id_from_.back() = static_cast<std::uint32_t>(blocks_.size());
}

PointStats BlockGrid::pointsOf(std::uint32_t id) const {
  // The grid cell holding the block: the last whose first block is at or before it.
  const auto after = std::upper_bound(cell_first_.begin(), cell_first_.end() - 1, id);
  const auto cell_number = static_cast<std::size_t>(after - cell_first_.begin()) - 1;
  const std::span<const Block> cell_blocks = map_->blocksAt(map_cell_[cell_number]);
  const PlaneBlock& block = blocks_[id];
  PointStats points;
  for (std::size_t k = block.map_first; k < std::size_t{block.map_first} + block.map_count; ++k) {
    points.merge(cell_blocks[k].points);
  }
  return points;
}

std::vector<std::uint32_t> BlockGrid::idsInMapOrder(std::span<const std::uint8_t> keep,
                                                    [[maybe_unused]] int threads) const {
  const auto cells = static_cast<std::int64_t>(map_cell_.size());
  FillVector<std::uint32_t> cell_of_map_cell(map_cell_.size());  // a bijection
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
  for (std::int64_t n = 0; n < cells; ++n) {
    cell_of_map_cell[map_cell_[static_cast<std::size_t>(n)]] = static_cast<std::uint32_t>(n);
  }
  constexpr std::int64_t kChunkCells = 8192;
  const std::int64_t chunks = (cells + kChunkCells - 1) / kChunkCells;
  std::vector<std::vector<std::uint32_t>> parts(static_cast<std::size_t>(chunks));
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (threads > 1)
  for (std::int64_t chunk = 0; chunk < chunks; ++chunk) {
    std::vector<std::uint32_t>& part = parts[static_cast<std::size_t>(chunk)];
    for (std::int64_t n = chunk * kChunkCells; n < std::min(cells, (chunk + 1) * kChunkCells); ++n) {
      const std::uint32_t cell = cell_of_map_cell[static_cast<std::size_t>(n)];
      for (std::uint32_t id = cell_first_[cell]; id < cell_first_[cell + 1]; ++id) {
        if (keep.empty() || keep[id] != 0) part.push_back(id);
      }
    }
  }
  std::size_t total = 0;
  for (const auto& part : parts) total += part.size();
  std::vector<std::uint32_t> ids;
  ids.reserve(total);
  for (const auto& part : parts) ids.insert(ids.end(), part.begin(), part.end());
  return ids;
}

}  // namespace mlmap
