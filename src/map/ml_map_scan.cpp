// The ML map's batch insertion of a scan: its points grouped by cell, each cell's run of
// points applied to it in parallel (the update rules: block_rules.cpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <utility>
#include <vector>

#include "block_rules.hpp"
#include "mlmap/error.hpp"
#include "mlmap/map/ml_map.hpp"

namespace mlmap {
namespace {

// Indices of `cells` in an order that groups equal cells, keeping scan order within
// each cell (a stable LSD radix sort on the cell's offset from the scan's corner).
std::vector<std::uint32_t> sortedByCell(const std::vector<CellIndex>& cells) {
  std::int64_t min_i = cells[0].i, max_i = cells[0].i, min_j = cells[0].j, max_j = cells[0].j;
  for (const CellIndex& cell : cells) {
    min_i = std::min<std::int64_t>(min_i, cell.i);
    max_i = std::max<std::int64_t>(max_i, cell.i);
    min_j = std::min<std::int64_t>(min_j, cell.j);
    max_j = std::max<std::int64_t>(max_j, cell.j);
  }
  const auto width = static_cast<std::uint64_t>(max_j - min_j + 1);
  const auto height = static_cast<std::uint64_t>(max_i - min_i + 1);
  std::vector<std::uint32_t> order(cells.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<std::uint32_t>(k);
  auto key = [&](std::uint32_t k) {
    return static_cast<std::uint64_t>(cells[k].i - min_i) * width +
           static_cast<std::uint64_t>(cells[k].j - min_j);
  };
  if (height > (std::numeric_limits<std::uint32_t>::max() / width)) {
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
    return order;
  }
  std::vector<std::uint32_t> keys(cells.size());
  for (std::size_t k = 0; k < keys.size(); ++k) keys[k] = static_cast<std::uint32_t>(key(static_cast<std::uint32_t>(k)));
  std::vector<std::uint32_t> buffer(order.size());
  std::vector<std::uint32_t> histogram(1U << 16);
  for (const int shift : {0, 16}) {
    std::fill(histogram.begin(), histogram.end(), 0U);
    for (const std::uint32_t k : order) ++histogram[(keys[k] >> shift) & 0xFFFFU];
    std::uint32_t total = 0;
    for (std::uint32_t& bucket : histogram) total += std::exchange(bucket, total);
    for (const std::uint32_t k : order) buffer[histogram[(keys[k] >> shift) & 0xFFFFU]++] = k;
    order.swap(buffer);
  }
  return order;
}

}  // namespace

void MLMap::insertScan(const Scan& scan) {
  // Points are grouped by cell with a stable sort before insertion: each cell then
  // sees its points in scan order, exactly as point-by-point insertion would, but the
  // hash grid is probed once per cell instead of once per point.
  const std::size_t count = scan.size();
  if (count == 0) return;
  if (count > std::numeric_limits<std::uint32_t>::max()) throw Error("scan too large (over 2^32 points)");
  std::vector<CellIndex> cells(count);
  std::vector<float> heights(count);
  std::vector<float> variances(count);
  std::vector<float> offsets_x(count);  // m, from the cell's centre
  std::vector<float> offsets_y(count);
  const auto signed_count = static_cast<std::int64_t>(count);
  bool all_valid = true;
#pragma omp parallel for schedule(static) reduction(&& : all_valid)
  for (std::int64_t k = 0; k < signed_count; ++k) {
    const auto index = static_cast<std::size_t>(k);
    const Point world = scan.worldPoint(index);
    const double variance = scan.variance(index);
    const auto cell = findCellOf(world.x(), world.y());
    const bool valid = cell && std::isfinite(world.z()) && variance > 0.0 && std::isfinite(variance);
    all_valid = all_valid && valid;
    cells[index] = valid ? *cell : CellIndex{};
    heights[index] = static_cast<float>(world.z());
    variances[index] = static_cast<float>(variance);
    if (valid) {
      const Eigen::Vector2d centre = cellCenter(*cell);
      offsets_x[index] = static_cast<float>(world.x() - centre.x());
      offsets_y[index] = static_cast<float>(world.y() - centre.y());
    }
  }
  if (!all_valid) {
    for (std::size_t index = 0; index < count; ++index) insert(scan.worldPoint(index), scan.variance(index));
    return;  // insert() throws at the first bad point; the points before it are in.
  }
  const std::vector<std::uint32_t> order = sortedByCell(cells);

  // Runs of points in one cell. Creating cells touches the hash grid: serial. A new
  // cell gets room for two blocks (floor and ceiling) so most runs fit in place.
  struct Run {
    std::size_t begin;
    std::size_t end;
    std::size_t cell_number;
  };
  std::vector<Run> runs;
  std::size_t new_cells = 0;
  for (std::size_t begin = 0; begin < count;) {
    const CellIndex cell = cells[order[begin]];
    std::size_t end = begin + 1;
    while (end < count && cells[order[end]] == cell) ++end;
    const std::size_t cell_number = findOrCreateCell(cell);
    new_cells += cells_[cell_number].capacity == 0 ? 1 : 0;
    runs.push_back(Run{begin, end, cell_number});
    begin = end;
  }
  // The arena grows once per scan, not once per doubling: each growth copies all of it.
  reserveArena(2 * new_cells);
  for (const Run& run : runs) {
    if (cells_[run.cell_number].capacity == 0) reserveCell(cells_[run.cell_number], 2);
  }

  // Each run updates its own cell, in parallel: in place in the cell's room in the
  // arena (no other run touches it), moving to a scratch copy only when a new block
  // would not fit (blocks are 60 bytes with their points' moments: copying each run
  // in and out is memory traffic); cells that outgrow their room are written back
  // afterwards.
  struct Outgrown {
    std::size_t cell_number;
    std::vector<Block> blocks;
  };
  std::vector<Outgrown> outgrown;
  const auto run_count = static_cast<std::int64_t>(runs.size());
  const auto reach = static_cast<float>(cell_size_);
  std::int64_t added = 0;
#pragma omp parallel reduction(+ : added)
  {
    std::vector<Block> scratch;
    std::vector<Outgrown> local_outgrown;
#pragma omp for schedule(dynamic, 512)
    for (std::int64_t r = 0; r < run_count; ++r) {
      const Run& run = runs[static_cast<std::size_t>(r)];
      Cell& cell = cells_[run.cell_number];
      Block* blocks = blocks_.data() + cell.first;
      std::size_t room = cell.capacity;
      int blocks_in_cell = cell.count;
      for (std::size_t k = run.begin; k < run.end; ++k) {
        if (static_cast<std::size_t>(blocks_in_cell) + 1 > room) {  // a measurement adds at most one block
          const std::size_t wanted = std::max<std::size_t>(2 * room, static_cast<std::size_t>(blocks_in_cell) + 1);
          if (blocks != scratch.data()) {
            scratch.resize(std::max(scratch.size(), wanted));
            std::copy_n(blocks, blocks_in_cell, scratch.begin());
          } else {
            scratch.resize(wanted);
          }
          blocks = scratch.data();
          room = scratch.size();
        }
        const std::uint32_t index = order[k];
        PointStats point;
        point.add(offsets_x[index], offsets_y[index], heights[index]);
        blocks_in_cell = addMeasurement(blocks, blocks_in_cell, heights[index], heights[index], variances[index],
                                        reach, point);
      }
      added += blocks_in_cell - cell.count;
      if (blocks_in_cell <= cell.capacity) {
        if (blocks != blocks_.data() + cell.first) std::copy_n(blocks, blocks_in_cell, blocks_.begin() + cell.first);
        cell.count = static_cast<std::uint16_t>(blocks_in_cell);
      } else {
        local_outgrown.push_back(Outgrown{run.cell_number, std::vector<Block>(blocks, blocks + blocks_in_cell)});
      }
    }
#pragma omp critical(mlmap_outgrown_cells)
    outgrown.insert(outgrown.end(), std::make_move_iterator(local_outgrown.begin()),
                    std::make_move_iterator(local_outgrown.end()));
  }
  // A cell that outgrew its room moves to the arena's end with room to grow as much
  // again: given only what it holds, it outgrows it at the next new surface and moves
  // again, each move leaving a dead run in the arena that every growth copies.
  const auto grownRoom = [](std::size_t blocks) { return std::min(kMaxBlocksPerCell, 2 * blocks); };
  std::size_t grown_room = 0;
  for (const Outgrown& grown : outgrown) grown_room += grownRoom(grown.blocks.size());
  reserveArena(grown_room);
  for (Outgrown& grown : outgrown) {
    Cell& cell = cells_[grown.cell_number];
    reserveCell(cell, grownRoom(grown.blocks.size()));
    std::copy(grown.blocks.begin(), grown.blocks.end(), blocks_.begin() + cell.first);
    cell.count = static_cast<std::uint16_t>(grown.blocks.size());
  }
  block_count_ = static_cast<std::size_t>(static_cast<std::int64_t>(block_count_) + added);
}

}  // namespace mlmap
