#include "mlmap/planes/patches.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include "counting_sort.hpp"
#include "fill_vector.hpp"
#include "floor_divide.hpp"
#include "outline_runs.hpp"
#include "raster_frame.hpp"

namespace mlmap {
namespace {

// Planes of fewer blocks are rasterised on one thread.
constexpr std::size_t kParallelBlocks = 20000;

class DisjointSets {
 public:
  explicit DisjointSets(std::size_t count) : parent_(count) {
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }
  std::size_t find(std::size_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void unite(std::size_t a, std::size_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<std::size_t> parent_;
};

// The footprints of the blocks on the plane's raster (raster_frame.hpp): raster cell
// (u, v) covers [u, u + 1) × [v, v + 1) cells. On the map grid a block covers its map
// cell. On the plane's basis (u level) a horizontal block covers the cell of its point,
// a vertical block the run of v its extent crosses at the u of its point. Block k's
// segment is segments[k].
struct Footprints {
  FillVector<Segment> segments;

  // `step`: cells of the grid per raster cell (the frame's cell size is step cells).
  Footprints(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const RasterFrame& frame,
             int threads = 1, int step = 1)
      : segments(blocks.size()) {
    const auto count = static_cast<std::int64_t>(blocks.size());
    [[maybe_unused]] const bool parallel = threads > 1 && blocks.size() >= kParallelBlocks;
    if (frame.on_map_grid) {
#pragma omp parallel for schedule(static) num_threads(std::max(threads, 1)) if (parallel)
      for (std::int64_t k = 0; k < count; ++k) {
        const CellIndex cell = grid.localCell(grid.blocks()[blocks[static_cast<std::size_t>(k)]].cell);
        const auto u = static_cast<std::int32_t>(floorDivide(cell.i, step));
        const auto v = static_cast<std::int32_t>(floorDivide(cell.j, step));
        segments[static_cast<std::size_t>(k)] = {u, v, v};
      }
      return;
    }
    const double cell = frame.cell_size;
    auto cellOf = [&](const Eigen::Vector3d& p) {
      const Eigen::Vector3d relative = p - frame.point;
      return Eigen::Vector2i(static_cast<std::int32_t>(std::floor(relative.dot(frame.u_axis) / cell)),
                             static_cast<std::int32_t>(std::floor(relative.dot(frame.v_axis) / cell)));
    };
#pragma omp parallel for schedule(static) num_threads(std::max(threads, 1)) if (parallel)
    for (std::int64_t k = 0; k < count; ++k) {
      const PlaneBlock& block = grid.blocks()[blocks[static_cast<std::size_t>(k)]];
      const Eigen::Vector3d centre = block.point.cast<double>();
      const Eigen::Vector2i centre_cell = cellOf(centre);
      Segment& segment = segments[static_cast<std::size_t>(k)];
      segment = {centre_cell.x(), centre_cell.y(), centre_cell.y()};
      if (!block.vertical) continue;
      // v grows with height (v_z ≥ 0): from the bottom's cell to the top's, the centre's
      // between them.
      segment.v_low = cellOf(Eigen::Vector3d(centre.x(), centre.y(), block.bottom)).y();
      segment.v_high = cellOf(Eigen::Vector3d(centre.x(), centre.y(), block.top)).y();
    }
  }
};

// Runs of segments in raster order (by u, then v_low): segments of a column whose rows
// are at most `join_gap` apart join into one run; with a `fine_gap` under it, also the
// runs at that gap, each inside one run (its parent). Numbered from 0.
struct RunList {
  std::vector<Segment> runs;
  std::vector<Segment> fine_runs;
  std::vector<std::uint32_t> parent_of_fine_run;

  // Returns the segment's run.
  std::uint32_t add(const Segment& segment, int join_gap, int fine_gap) {
    if (runs.empty() || runs.back().u != segment.u ||
        static_cast<std::int64_t>(segment.v_low) - runs.back().v_high > join_gap) {
      runs.push_back(segment);
    } else {
      runs.back().v_high = std::max(runs.back().v_high, segment.v_high);
    }
    const auto run = static_cast<std::uint32_t>(runs.size() - 1);
    if (fine_gap <= 0) return run;
    // A new run starts a new fine run too (its gap is wider than the fine one).
    if (fine_runs.empty() || fine_runs.back().u != segment.u ||
        static_cast<std::int64_t>(segment.v_low) - fine_runs.back().v_high > fine_gap) {
      fine_runs.push_back(segment);
      parent_of_fine_run.push_back(run);
    } else {
      fine_runs.back().v_high = std::max(fine_runs.back().v_high, segment.v_high);
    }
    return run;
  }
};

// The footprints merged per raster column: the RunList of all of them. Runs are
// ordered by u, then v, and disjoint; run_of_segment names each segment's run.
struct ColumnRuns : RunList {
  FillVector<std::uint32_t> run_of_segment;

  ColumnRuns(const FillVector<Segment>& segments, int join_gap, int fine_gap = 0, int threads = 1)
      : run_of_segment(segments.size()) {
    // A level plane's blocks (ids ascending) on the map's grid come in raster order.
    if (std::is_sorted(segments.begin(), segments.end(), [](const Segment& a, const Segment& b) {
          return a.u < b.u || (a.u == b.u && a.v_low < b.v_low);
        })) {
      fromOrdered(segments, join_gap, fine_gap, threads > 1 && segments.size() >= kParallelBlocks ? threads : 1);
      return;
    }
    struct Numbered {
      Segment segment;
      std::uint32_t number;
    };
    FillVector<Numbered> order(segments.size());
    const auto count = static_cast<std::int64_t>(segments.size());
#pragma omp parallel for schedule(static) num_threads(std::max(threads, 1)) if (threads > 1 && segments.size() >= kParallelBlocks)
    for (std::int64_t n = 0; n < count; ++n) {
      order[static_cast<std::size_t>(n)] = {segments[static_cast<std::size_t>(n)], static_cast<std::uint32_t>(n)};
    }
    stableSortBy(order, [](const Numbered& item) { return item.segment.v_low; }, threads);
    stableSortBy(order, [](const Numbered& item) { return item.segment.u; }, threads);
    for (const auto& [segment, n] : order) run_of_segment[n] = add(segment, join_gap, fine_gap);
  }

 private:
  // Segments in raster order, in slices that start at a new column (no run crosses
  // one), a slice's runs on a thread each, then joined in slice order.
  void fromOrdered(const FillVector<Segment>& segments, int join_gap, int fine_gap, int slices) {
    std::vector<std::size_t> bounds(static_cast<std::size_t>(slices) + 1, segments.size());
    bounds[0] = 0;
    for (std::size_t s = 1; s < bounds.size() - 1; ++s) {
      std::size_t at = std::max(bounds[s - 1], segments.size() * s / static_cast<std::size_t>(slices));
      while (at > 0 && at < segments.size() && segments[at].u == segments[at - 1].u) ++at;
      bounds[s] = at;
    }
    std::vector<RunList> parts(static_cast<std::size_t>(slices));
#pragma omp parallel for schedule(static, 1) num_threads(slices) if (slices > 1)
    for (int s = 0; s < slices; ++s) {
      const auto slice = static_cast<std::size_t>(s);
      for (std::size_t n = bounds[slice]; n < bounds[slice + 1]; ++n) {
        run_of_segment[n] = parts[slice].add(segments[n], join_gap, fine_gap);
      }
    }
    if (slices == 1) {
      static_cast<RunList&>(*this) = std::move(parts[0]);
      return;
    }
    std::vector<std::uint32_t> first_run(parts.size(), 0);
    for (std::size_t s = 0; s < parts.size(); ++s) {
      first_run[s] = static_cast<std::uint32_t>(runs.size());
      runs.insert(runs.end(), parts[s].runs.begin(), parts[s].runs.end());
      fine_runs.insert(fine_runs.end(), parts[s].fine_runs.begin(), parts[s].fine_runs.end());
      for (const std::uint32_t parent : parts[s].parent_of_fine_run) parent_of_fine_run.push_back(first_run[s] + parent);
    }
#pragma omp parallel for schedule(static, 1) num_threads(slices)
    for (int s = 0; s < slices; ++s) {
      const auto slice = static_cast<std::size_t>(s);
      for (std::size_t n = bounds[slice]; n < bounds[slice + 1]; ++n) run_of_segment[n] += first_run[slice];
    }
  }
};

}  // namespace

void planeBasis(const Eigen::Vector3d& normal, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  u = Eigen::Vector3d::UnitZ().cross(normal);
  // A level plane's (RasterFrame's rule): z × n too short to be a basis.
  if (u.norm() < RasterFrame::kLevelSine) u = normal.cross(Eigen::Vector3d::UnitX()).cross(normal);
  u.normalize();
  v = normal.cross(u).normalized();
}

SplitPatches splitWithOutlineRuns(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                  const Eigen::Vector3d& normal, const Eigen::Vector3d& point, int gap_cells,
                                  int threads) {
  SplitPatches split;
  if (blocks.empty()) return split;
  const Footprints footprints(grid, blocks, RasterFrame(normal, point, grid.cellSize()), threads);
  const FillVector<Segment>& segments = footprints.segments;
  // Cells are connected within gap_cells (Chebyshev). Not cell by cell (a wall at 2 cm
  // rasterises to over half a million cells): in each raster column u, segments less
  // than gap_cells apart join into runs, and runs of columns up to gap_cells apart
  // connect when their closest cells are: when neither starts more than gap_cells past
  // the other's end. (Both runs' ends are occupied, and no cell inside a run is more
  // than gap_cells / 2 from an occupied one.) The touching runs the outlines are traced
  // on come out of the same pass.
  const ColumnRuns column_runs(segments, gap_cells, gap_cells > 1 ? 1 : 0, threads);
  const std::vector<Segment>& runs = column_runs.runs;
  const FillVector<std::uint32_t>& run_of_segment = column_runs.run_of_segment;
  // The runs of each column: [column_first[u − min_u], column_first[u − min_u + 1]).
  const std::int32_t min_u = runs.front().u;
  const auto columns = static_cast<std::size_t>(static_cast<std::int64_t>(runs.back().u) - min_u + 1);
  std::vector<std::uint32_t> column_first(columns + 1, 0);
  for (const Segment& run : runs) ++column_first[static_cast<std::size_t>(run.u - min_u) + 1];
  for (std::size_t c = 1; c <= columns; ++c) column_first[c] += column_first[c - 1];
  DisjointSets sets(runs.size());
  for (std::size_t column = 0; column < columns; ++column) {
    for (std::size_t other = column + 1; other <= std::min(columns - 1, column + static_cast<std::size_t>(gap_cells));
         ++other) {
      // Both columns' runs are ordered by v and disjoint: one sweep pairs them.
      std::uint32_t b = column_first[other];
      for (std::uint32_t a = column_first[column]; a < column_first[column + 1]; ++a) {
        while (b < column_first[other + 1] && static_cast<std::int64_t>(runs[a].v_low) - runs[b].v_high > gap_cells) ++b;
        for (std::uint32_t c = b;
             c < column_first[other + 1] && static_cast<std::int64_t>(runs[c].v_low) - runs[a].v_high <= gap_cells; ++c) {
          sets.unite(a, c);
        }
      }
    }
  }
  // Patches in the order of their first block (the order of the blocks' first raster
  // cells), then largest first.
  std::vector<std::int32_t> patch_of_root(runs.size(), -1);
  std::vector<std::uint32_t> root_of_run(runs.size());
  for (std::size_t r = 0; r < runs.size(); ++r) root_of_run[r] = static_cast<std::uint32_t>(sets.find(r));
  // Each block's component and surface on all threads; then, in block order, the
  // patches numbered, counted and their surfaces summed; then each patch's blocks, in
  // block order, placed on all threads (the counting sort's placement).
  const auto block_count = static_cast<std::int64_t>(blocks.size());
  const bool parallel = threads > 1 && blocks.size() >= kParallelBlocks;
  FillVector<std::uint32_t> patch_of_block(blocks.size());  // its root first
  FillVector<float> surface_of(blocks.size());
#pragma omp parallel for schedule(static) num_threads(std::max(threads, 1)) if (parallel)
  for (std::int64_t k = 0; k < block_count; ++k) {
    const auto n = static_cast<std::size_t>(k);
    patch_of_block[n] = root_of_run[run_of_segment[n]];
    surface_of[n] = grid.blocks()[blocks[n]].surface;
  }
  std::vector<std::size_t> patch_sizes;
  std::vector<double> surfaces;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const std::uint32_t root = patch_of_block[k];
    if (patch_of_root[root] < 0) {
      patch_of_root[root] = static_cast<std::int32_t>(patch_sizes.size());
      patch_sizes.push_back(0);
      surfaces.push_back(0.0);
    }
    const auto patch = static_cast<std::size_t>(patch_of_root[root]);
    patch_of_block[k] = static_cast<std::uint32_t>(patch);
    ++patch_sizes[patch];
    surfaces[patch] += surface_of[k];
  }
  std::vector<Patch> patches(patch_sizes.size());
  std::vector<std::size_t> first_position(patches.size(), 0);  // of each patch, its blocks laid end to end
  for (std::size_t k = 0; k < patches.size(); ++k) {
    patches[k].blocks.resize(patch_sizes[k]);
    patches[k].surface = surfaces[k];
    if (k + 1 < patches.size()) first_position[k + 1] = first_position[k] + patch_sizes[k];
  }
  placeStably(
      blocks.size(), patches.size(), [&](std::size_t k) { return static_cast<std::size_t>(patch_of_block[k]); },
      [&](std::size_t k, std::uint32_t position) {
        const std::uint32_t patch = patch_of_block[k];
        patches[patch].blocks[position - first_position[patch]] = blocks[k];
      },
      parallel ? threads : 1);
  // Each patch's touching runs (at a gap of one cell the runs themselves; at none, the
  // outline's runs are not known here and stay empty).
  std::vector<std::vector<Segment>> outline_runs(patches.size());
  if (gap_cells > 1) {
    for (std::size_t f = 0; f < column_runs.fine_runs.size(); ++f) {
      const auto patch = static_cast<std::size_t>(patch_of_root[root_of_run[column_runs.parent_of_fine_run[f]]]);
      outline_runs[patch].push_back(column_runs.fine_runs[f]);
    }
  } else if (gap_cells == 1) {
    for (std::size_t r = 0; r < runs.size(); ++r) {
      outline_runs[static_cast<std::size_t>(patch_of_root[root_of_run[r]])].push_back(runs[r]);
    }
  }
  std::vector<std::size_t> largest_first(patches.size());
  std::iota(largest_first.begin(), largest_first.end(), std::size_t{0});
  std::stable_sort(largest_first.begin(), largest_first.end(),
                   [&](std::size_t a, std::size_t b) { return patches[a].surface > patches[b].surface; });
  for (const std::size_t k : largest_first) {
    split.patches.push_back(std::move(patches[k]));
    split.outline_runs.push_back(std::move(outline_runs[k]));
  }
  return split;
}

std::vector<Patch> splitIntoPatches(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                    const Eigen::Vector3d& normal, const Eigen::Vector3d& point,
                                    int gap_cells, int threads) {
  return splitWithOutlineRuns(grid, blocks, normal, point, gap_cells, threads).patches;
}

std::vector<Segment> runsOf(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                            const Eigen::Vector3d& normal, const Eigen::Vector3d& point, int step) {
  if (blocks.empty()) return {};
  step = std::max(step, 1);
  return ColumnRuns(Footprints(grid, blocks, RasterFrame(normal, point, grid.cellSize() * step), 1, step).segments, 1)
      .runs;
}

std::vector<Eigen::Vector3d> outlineOf(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                       const Eigen::Vector3d& normal, const Eigen::Vector3d& point, int step) {
  step = std::max(step, 1);
  return outlineOfRuns(runsOf(grid, blocks, normal, point, step), grid.cellSize() * step, normal, point);
}

}  // namespace mlmap
