#include "mlmap/planes/direction_vectors.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "smallest_axis.hpp"
#include "wall_line.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap {
namespace {

// The moment sums of a block run over its neighbours, and which neighbours count
// depends on the block (its height): a branch per neighbour would mispredict on every
// table edge. Instead the neighbours sit four to a vector (GCC/Clang vector extensions,
// SSE2 or NEON without -march), field by field, and each block's sums take four at a
// time, masked to zero where a neighbour does not count.
using Lanes = float __attribute__((vector_size(16)));
using LaneMask = std::int32_t __attribute__((vector_size(16)));

Lanes keepIf(LaneMask keep, Lanes terms) { return reinterpret_cast<Lanes>(reinterpret_cast<LaneMask>(terms) & keep); }

float sumOf(Lanes lanes) { return (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]); }

// The neighbourhood of a cell is 2r + 1 columns of 2r + 1 cells; the next cell of its
// row shares all but one column with it. So the blocks are gathered a column at a time
// and kept while the window slides along the row. A block sits where its points are
// (PlaneBlock::offset_x, offset_y): its position across is its cell's offset from the
// window's cell (small integers) plus its own offset, in cell units. Within a column
// dy holds both; the column's dx enters when its blocks are summed. A column's blocks,
// four to a vector, the last vector padded with blocks that never count:
struct Column {
  std::int64_t j = std::numeric_limits<std::int64_t>::min();  // the grid column it holds
  std::vector<Lanes> level_dx, level_dy, level_top, level_z;  // horizontal blocks
  std::vector<Lanes> vertical_dx, vertical_dy, vertical_top, vertical_bottom;
  std::size_t levels = 0;
  std::size_t verticals = 0;

  void clear(std::int64_t column) {
    j = column;
    levels = verticals = 0;
    for (std::vector<Lanes>* lanes : {&level_dx, &level_dy, &level_top, &level_z, &vertical_dx, &vertical_dy,
                                      &vertical_top, &vertical_bottom}) {
      lanes->clear();
    }
  }
  void add(const PlaneBlock& block, float dy) {
    const float infinity = std::numeric_limits<float>::infinity();
    if (block.vertical) {
      if (verticals % 4 == 0) {
        vertical_dx.push_back(Lanes{});
        vertical_dy.push_back(Lanes{});
        vertical_top.push_back(Lanes{} - infinity);  // overlaps nothing
        vertical_bottom.push_back(Lanes{} + infinity);
      }
      const std::size_t lane = verticals++ % 4;
      vertical_dx.back()[lane] = block.offset_x;
      vertical_dy.back()[lane] = dy + block.offset_y;
      vertical_top.back()[lane] = block.top;
      vertical_bottom.back()[lane] = block.bottom;
    } else {
      if (levels % 4 == 0) {
        level_dx.push_back(Lanes{});
        level_dy.push_back(Lanes{});
        level_top.push_back(Lanes{} + infinity);  // at no height near a block's
        level_z.push_back(Lanes{});
      }
      const std::size_t lane = levels++ % 4;
      level_dx.back()[lane] = block.offset_x;
      level_dy.back()[lane] = dy + block.offset_y;
      level_top.back()[lane] = block.top;
      level_z.back()[lane] = block.point.z();
    }
  }
};

// A block's sums over its kept neighbours: in cell units across (relative to its
// cell's centre), metres up relative to its height. Each is four partial sums, added
// up at the end.
struct Moments {
  Lanes n{}, x{}, y{}, xx{}, xy{}, yy{};
  Lanes z{}, xz{}, yz{}, zz{};

  // Four neighbours: `keep` masks the ones that count; x, y across and z up.
  void add(LaneMask keep, Lanes x_lanes, Lanes y_lanes, Lanes z_lanes) {
    const Lanes kx = keepIf(keep, x_lanes);
    const Lanes ky = keepIf(keep, y_lanes);
    const Lanes kz = keepIf(keep, z_lanes);
    n += keepIf(keep, Lanes{} + 1.0F);
    x += kx;
    y += ky;
    xx += kx * x_lanes;
    xy += kx * y_lanes;
    yy += ky * y_lanes;
    z += kz;
    xz += kz * x_lanes;
    yz += kz * y_lanes;
    zz += kz * z_lanes;
  }
};

Direction horizontalDirection(const PlaneBlock& self, const Column* const* window, int radius, float height_tolerance,
                              double cell, double min_spread) {
  Moments sums;
  for (int c = 0; c <= 2 * radius; ++c) {
    const Column& column = *window[c];
    const auto dx = static_cast<float>(c - radius);
    for (std::size_t q = 0; q < column.level_top.size(); ++q) {
      const Lanes rise = column.level_top[q] - self.top;
      const LaneMask keep = (rise < height_tolerance) & (rise > -height_tolerance);
      sums.add(keep, column.level_dx[q] + dx, column.level_dy[q], column.level_z[q] - self.point.z());
    }
  }
  const double n = sumOf(sums.n);
  if (n < 3.0) return {};
  const double area = cell * cell;
  const Eigen::Vector3d mean = Eigen::Vector3d(sumOf(sums.x) * cell, sumOf(sums.y) * cell, sumOf(sums.z)) / n;
  const double xy = sumOf(sums.xy) * area;
  const double xz = sumOf(sums.xz) * cell;
  const double yz = sumOf(sums.yz) * cell;
  Eigen::Matrix3d covariance;
  covariance << sumOf(sums.xx) * area, xy, xz, xy, sumOf(sums.yy) * area, yz, xz, yz, sumOf(sums.zz);
  covariance = covariance / n - mean * mean.transpose();
  const SmallestAxis smallest = smallestAxis(covariance);
  // The neighbourhood must spread in two directions, or its normal is arbitrary.
  if (smallest.middle_eigenvalue < min_spread) return {};
  return {orientConsistently(smallest.axis.cast<float>()),
          tiltOf(smallest.smallest_eigenvalue, smallest.middle_eigenvalue, n, 3.0)};
}

Direction verticalDirection(const PlaneBlock& self, const Column* const* window, int radius, double cell,
                            double min_spread, float corner_reach, double max_residual) {
  Moments sums;
  for (int c = 0; c <= 2 * radius; ++c) {
    const Column& column = *window[c];
    const auto dx = static_cast<float>(c - radius);
    for (std::size_t q = 0; q < column.vertical_top.size(); ++q) {
      // Their extents overlap.
      const LaneMask keep = (column.vertical_bottom[q] <= self.top) & (column.vertical_top[q] >= self.bottom);
      sums.add(keep, column.vertical_dx[q] + dx, column.vertical_dy[q], Lanes{});
    }
  }
  const double n = sumOf(sums.n);
  if (n < 2.0) return {};
  const Eigen::Vector2d mean = Eigen::Vector2d(sumOf(sums.x), sumOf(sums.y)) * cell / n;
  Eigen::Matrix2d covariance;
  covariance << sumOf(sums.xx), sumOf(sums.xy), sumOf(sums.xy), sumOf(sums.yy);
  covariance = covariance * (cell * cell) / n - mean * mean.transpose();
  const Direction line = lineDirection(covariance, n, min_spread);
  // Blocks off the line by more than the reach on average: the window holds a corner.
  // (A straight wall's scatter about its line is its blocks' noise, far less.)
  if (corner_reach <= 0.0F || !(smallerEigenvalue(covariance) > std::pow(corner_reach * cell, 2))) return line;
  thread_local std::vector<Eigen::Vector2f> positions;
  positions.clear();
  for (int c = 0; c <= 2 * radius; ++c) {
    const Column& column = *window[c];
    const auto dx = static_cast<float>(c - radius);
    for (std::size_t q = 0; q < column.vertical_top.size(); ++q) {
      for (int lane = 0; lane < 4; ++lane) {
        if (column.vertical_bottom[q][lane] <= self.top && column.vertical_top[q][lane] >= self.bottom) {
          positions.emplace_back(column.vertical_dx[q][lane] + dx, column.vertical_dy[q][lane]);
        }
      }
    }
  }
  const Direction corner =
      cornerDirection(positions, Eigen::Vector2f(self.offset_x, self.offset_y), corner_reach, max_residual, cell, min_spread);
  return corner.vector.squaredNorm() > 0.0F ? corner : line;
}

Direction directionOf(const PlaneBlock& block, const Column* const* window, int radius, float height_tolerance,
                      bool corners, double cell, double min_spread) {
  // Cells: a block further off its line than this is not on it (half ε: a wall's blocks
  // scatter about theirs by their points' noise, ε is 3 σ or more), and never nearer
  // than a third of a cell. m: the RMS scatter about their line that the blocks of one
  // straight face show at most, ε / 3 (simulated corridor and lab at 10 cm cells, turned
  // 5-20°: ε / 6 lost the stair risers again, no check let the lab's pillar through as
  // facets).
  const float corner_reach = corners ? std::max(0.35F, 0.5F * height_tolerance / static_cast<float>(cell)) : 0.0F;
  const double max_residual = height_tolerance / 3.0;
  return block.vertical ? verticalDirection(block, window, radius, cell, min_spread, corner_reach, max_residual)
                        : horizontalDirection(block, window, radius, height_tolerance, cell, min_spread);
}

// Column c of the window of radius `radius` round row i: the blocks of cells i ± radius.
void fillColumn(const BlockGrid& grid, Column& column, std::int64_t i, int radius, std::int64_t c) {
  column.clear(c);
  grid.forEachInCells(i - radius, i + radius, c, c, [&](std::uint32_t other) {
    const PlaneBlock& block = grid.blocks()[other];
    column.add(block, static_cast<float>(block.cell.i - i));
  });
}

}  // namespace

Eigen::Vector3f orientConsistently(const Eigen::Vector3f& normal) {
  const float length = normal.norm();
  if (!(length > 0.0F)) return Eigen::Vector3f::Zero();
  Eigen::Vector3f unit = normal / length;
  // Pick the sign by the largest component, with z first so near-horizontal surfaces
  // (|n_z| large) always point up.
  if (std::abs(unit.z()) >= std::max(std::abs(unit.x()), std::abs(unit.y()))) {
    if (unit.z() < 0.0F) unit = -unit;
  } else if (std::abs(unit.x()) >= std::abs(unit.y())) {
    if (unit.x() < 0.0F) unit = -unit;
  } else if (unit.y() < 0.0F) {
    unit = -unit;
  }
  return unit;
}

namespace {

// The window of radius `radius` about `cell`, filled column by column into the scratch
// `columns` (2 radius + 1 of them at least), `window` pointing at them.
void fillWindow(const BlockGrid& grid, CellIndex cell, int radius, std::vector<Column>& columns,
                std::vector<const Column*>& window) {
  for (int c = 0; c <= 2 * radius; ++c) {
    fillColumn(grid, columns[static_cast<std::size_t>(c)], cell.i, radius, std::int64_t{cell.j} - radius + c);
    window[static_cast<std::size_t>(c)] = &columns[static_cast<std::size_t>(c)];
  }
}

// One uncertain level block's window, wider a cell at a time from `best` (its window
// of r cells'): the most certain direction it reaches. `columns`, `window`: scratch of
// 2 max_radius + 1 columns.
Direction widened(const BlockGrid& grid, const DirectionConfig& config, double min_spread, const PlaneBlock& block,
                  Direction best, std::vector<Column>& columns, std::vector<const Column*>& window) {
  for (int radius = config.radius + 1; radius <= config.max_radius; ++radius) {
    fillWindow(grid, block.cell, radius, columns, window);
    const Direction wider =
        directionOf(block, window.data(), radius, config.height_tolerance, config.corners, grid.cellSize(), min_spread);
    if (wider.tilt < best.tilt) best = wider;
    if (best.tilt <= config.max_tilt) break;
  }
  return best;
}

bool widens(const DirectionConfig& config) { return config.max_radius > config.radius && config.max_tilt > 0.0; }

// Whether a block's window of r cells leaves its direction uncertain enough to widen.
bool uncertain(const DirectionConfig& config, const PlaneBlock& block, float tilt) {
  return tilt > config.max_tilt && std::isfinite(tilt) && !block.vertical;
}

// The uncertain level blocks' windows, a cell wider at a time: each block keeps the most
// certain direction it reaches, and stops once within max_tilt. Few blocks on most
// maps, so each builds its own window rather than sliding one along the rows. Only
// level blocks whose window held enough blocks to measure its scatter (a finite tilt):
// a window too small to tell is the edge of a surface or a lone object, which a wider
// window only mixes with its surroundings; and not walls, whose uncertain windows hold
// corners (widening them cost the simulated scenes at 10 cm cells 0.04-0.14 F1).
void widenUncertain(const BlockGrid& grid, const DirectionConfig& config, double min_spread, DirectionField& field) {
  std::vector<Eigen::Vector3f>& directions = field.vectors;
  std::vector<float>& tilts = field.tilts;
  std::vector<std::uint32_t> ids;
  for (std::uint32_t id = 0; id < tilts.size(); ++id) {
    if (uncertain(config, grid.blocks()[id], tilts[id])) ids.push_back(id);
  }
  const auto count = static_cast<std::int64_t>(ids.size());
#ifdef _OPENMP
  const int threads = config.threads > 0 ? config.threads : omp_get_max_threads();
#endif
#pragma omp parallel num_threads(threads)
  {
    std::vector<Column> columns(static_cast<std::size_t>(2 * config.max_radius + 1));
    std::vector<const Column*> window(columns.size());
#pragma omp for schedule(dynamic, 64)
    for (std::int64_t k = 0; k < count; ++k) {
      const std::uint32_t id = ids[static_cast<std::size_t>(k)];
      // Still uncertain at the widest: the most certain window's.
      const Direction best =
          widened(grid, config, min_spread, grid.blocks()[id], Direction{directions[id], tilts[id]}, columns, window);
      directions[id] = best.vector;
      tilts[id] = static_cast<float>(best.tilt);
    }
  }
}

}  // namespace

std::vector<Eigen::Vector3f> directionVectors(const BlockGrid& grid, const DirectionConfig& config) {
  return directionField(grid, config).vectors;
}

DirectionField directionField(const BlockGrid& grid, const DirectionConfig& config) {
  // Not zeroed first: the loop writes every block's (each lies in one cell), and Eigen's
  // vectors are left uninitialised by their constructor, so the pages are first touched
  // by the threads that fill them.
  DirectionField field;
  std::vector<Eigen::Vector3f>& directions = field.vectors;
  std::vector<float>& tilts = field.tilts;
  directions.resize(grid.size());
  tilts.resize(grid.size());
  const bool widen = widens(config);
  const double cell = grid.cellSize();
  const double min_spread = 0.1 * cell * cell;
  const int radius = std::max(0, config.radius);
  const auto& blocks = grid.blocks();
  // Cells are numbered row by row: each row's first cell number.
  std::vector<std::size_t> row_first;
  for (std::size_t n = 0; n < grid.cellCount(); ++n) {
    if (n == 0 || blocks[grid.firstBlockOfCell(n)].cell.i != blocks[grid.firstBlockOfCell(n - 1)].cell.i) {
      row_first.push_back(n);
    }
  }
  row_first.push_back(grid.cellCount());
  const auto rows = static_cast<std::int64_t>(row_first.size()) - 1;
#ifdef _OPENMP
  const int threads = config.threads > 0 ? config.threads : omp_get_max_threads();
#endif
#pragma omp parallel num_threads(threads)
  {
    // The columns the window has seen, each in the slot of its column number modulo the width.
    std::vector<Column> slots(static_cast<std::size_t>(2 * radius + 1));
    std::vector<const Column*> window(slots.size());
#pragma omp for schedule(dynamic, 1)
    for (std::int64_t row = 0; row < rows; ++row) {
      for (Column& slot : slots) slot.j = std::numeric_limits<std::int64_t>::min();
      const auto first = row_first[static_cast<std::size_t>(row)];
      const std::int64_t i = blocks[grid.firstBlockOfCell(first)].cell.i;
      for (std::size_t n = first; n < row_first[static_cast<std::size_t>(row) + 1]; ++n) {
        const std::uint32_t begin = grid.firstBlockOfCell(n);
        const std::uint32_t end = grid.firstBlockOfCell(n + 1);
        const std::int64_t j = blocks[begin].cell.j;
        for (std::int64_t c = j - radius; c <= j + radius; ++c) {
          const auto width = static_cast<std::int64_t>(slots.size());
          Column& slot = slots[static_cast<std::size_t>(((c % width) + width) % width)];
          window[static_cast<std::size_t>(c - (j - radius))] = &slot;
          if (slot.j != c) fillColumn(grid, slot, i, radius, c);
        }
        for (std::uint32_t id = begin; id < end; ++id) {
          const Direction direction =
              directionOf(blocks[id], window.data(), radius, config.height_tolerance, config.corners, cell, min_spread);
          directions[id] = direction.vector;
          tilts[id] = static_cast<float>(direction.tilt);
        }
      }
    }
  }
  if (widen) widenUncertain(grid, config, min_spread, field);
  return field;
}

DirectionField updatedDirectionField(const BlockGrid& grid, const DirectionConfig& config, DirectionField earlier,
                                     const std::vector<std::uint32_t>& changed) {
  const bool widen = widens(config);
  const int radius = std::max(0, config.radius);
  // A block's direction reads the blocks of its window only: of r cells, and of up to
  // max_radius where it widens.
  const int reach = widen ? std::max(radius, config.max_radius) : radius;
  std::vector<std::uint8_t> stale(grid.size(), 0);
  std::size_t stale_count = 0;
  for (const std::uint32_t id : changed) {
    grid.forEachNeighbour(grid.blocks()[id].cell, reach, [&](std::uint32_t other) {
      stale_count += stale[other] == 0 ? 1 : 0;
      stale[other] = 1;
    });
  }
  // Most of the map: the sliding windows of a whole pass are cheaper than a window each.
  if (2 * stale_count > grid.size() || earlier.vectors.size() != grid.size()) return directionField(grid, config);
  // The stale blocks a cell at a time (ids ascend cell by cell): each cell's window once.
  std::vector<std::uint32_t> cell_starts;
  for (std::uint32_t id = 0; id < grid.size(); ++id) {
    if (stale[id] == 0) continue;
    if (cell_starts.empty() || !(grid.blocks()[cell_starts.back()].cell == grid.blocks()[id].cell)) cell_starts.push_back(id);
  }
  const double cell = grid.cellSize();
  const double min_spread = 0.1 * cell * cell;
  const auto cells = static_cast<std::int64_t>(cell_starts.size());
  const auto& blocks = grid.blocks();
#ifdef _OPENMP
  const int threads = config.threads > 0 ? config.threads : omp_get_max_threads();
#endif
#pragma omp parallel num_threads(threads)
  {
    std::vector<Column> columns(static_cast<std::size_t>(2 * std::max(radius, config.max_radius) + 1));
    std::vector<const Column*> window(columns.size());
#pragma omp for schedule(dynamic, 16)
    for (std::int64_t n = 0; n < cells; ++n) {
      const std::uint32_t begin = cell_starts[static_cast<std::size_t>(n)];
      const CellIndex here = blocks[begin].cell;
      fillWindow(grid, here, radius, columns, window);
      std::vector<std::uint32_t> uncertain_ids;
      for (std::uint32_t id = begin; id < grid.size() && blocks[id].cell == here; ++id) {
        const Direction direction =
            directionOf(blocks[id], window.data(), radius, config.height_tolerance, config.corners, cell, min_spread);
        earlier.vectors[id] = direction.vector;
        earlier.tilts[id] = static_cast<float>(direction.tilt);
        if (widen && uncertain(config, blocks[id], earlier.tilts[id])) uncertain_ids.push_back(id);
      }
      // After the cell's r-cell windows: widening refills the scratch columns.
      for (const std::uint32_t id : uncertain_ids) {
        const Direction best =
            widened(grid, config, min_spread, blocks[id], Direction{earlier.vectors[id], earlier.tilts[id]}, columns, window);
        earlier.vectors[id] = best.vector;
        earlier.tilts[id] = static_cast<float>(best.tilt);
      }
    }
  }
  return earlier;
}

}  // namespace mlmap
