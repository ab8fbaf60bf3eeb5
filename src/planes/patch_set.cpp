#include "patch_set.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "mlmap/planes/direction_vectors.hpp"
#include "floor_divide.hpp"
#include "pca_sums.hpp"
#include "raster_frame.hpp"
#include "raster_step.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap {
namespace {

// The outline lies on the plane the patch was split on: put it on the patch's own, and the
// bounds round `cell_corners` (every piece's; cornersOfRuns) there too, or round the outline.
void placeOutline(Plane& plane, const std::vector<Eigen::Vector3d>& corners,
                  const std::vector<Eigen::Vector3d>& cell_corners = {}) {
  const auto onPlane = [&](const Eigen::Vector3d& corner) -> Eigen::Vector3d {
    return corner - plane.normal * (plane.normal.dot(corner) + plane.offset);
  };
  plane.outline.clear();
  for (const Eigen::Vector3d& corner : corners) plane.outline.push_back(onPlane(corner));
  plane.bounds.setEmpty();
  for (const Eigen::Vector3d& corner : cell_corners) plane.bounds.extend(onPlane(corner));
  for (const Eigen::Vector3d& corner : plane.outline) plane.bounds.extend(corner);
}

// The area the blocks cover on the plane, not their surface: a wall on a cell boundary
// has blocks in both cell columns, each of the wall's full height, and a wall at 45°
// crosses √2 cells per cell of its length. Each block stands for its cell: on a level
// plane the cells are counted (over |n_z| for its slope); on any other its cell's
// extent along the plane's level axis u times its own extent up the plane (v) is a
// rectangle, and the area of the rectangles' union is swept along u. With `step` > 1
// (Patch::raster_step) each block stands for a cell `step` cells wide.
double coveredArea(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
                   const Eigen::Vector3d& point, int step) {
  const double cell = grid.cellSize() * step;
  if (blocks.empty()) return 0.0;
  if (Eigen::Vector3d::UnitZ().cross(normal).norm() < RasterFrame::kLevelSine) {
    if (step > 1) {
      std::vector<std::pair<std::int64_t, std::int64_t>> cells;
      for (const std::uint32_t id : blocks) {
        cells.emplace_back(floorDivide(grid.blocks()[id].cell.i, step), floorDivide(grid.blocks()[id].cell.j, step));
      }
      std::sort(cells.begin(), cells.end());
      const auto distinct = static_cast<double>(std::unique(cells.begin(), cells.end()) - cells.begin());
      return distinct * cell * cell / std::abs(normal.z());
    }
    // Block ids run row by row over the grid, a cell's blocks together: a cell's
    // blocks in the patch are consecutive in its ascending list.
    double distinct = 0.0;
    const CellIndex* previous = nullptr;
    for (const std::uint32_t id : blocks) {
      const CellIndex& c = grid.blocks()[id].cell;
      if (previous == nullptr || !(c == *previous)) distinct += 1.0;
      previous = &c;
    }
    return distinct * cell * cell / std::abs(normal.z());
  }
  Eigen::Vector3d u_axis;
  Eigen::Vector3d v_axis;
  planeBasis(normal, u_axis, v_axis);
  const double half_width = 0.5 * cell * (std::abs(u_axis.x()) + std::abs(u_axis.y()));
  struct Rectangle {
    double u_low, u_high, v_low, v_high;
  };
  std::vector<Rectangle> rectangles;
  rectangles.reserve(blocks.size());
  for (const std::uint32_t id : blocks) {
    const PlaneBlock& block = grid.blocks()[id];
    const Eigen::Vector2d centre = grid.cellCentre(block.cell);
    const double u = (Eigen::Vector3d(centre.x(), centre.y(), block.point.z()) - point).dot(u_axis);
    double low = (Eigen::Vector3d(centre.x(), centre.y(), block.bottom) - point).dot(v_axis);
    double high = (Eigen::Vector3d(centre.x(), centre.y(), block.top) - point).dot(v_axis);
    if (low > high) std::swap(low, high);
    if (!block.vertical) {
      low -= 0.5 * cell;
      high += 0.5 * cell;
    }
    rectangles.push_back({u - half_width, u + half_width, low, high});
  }
  struct Event {
    double u;
    std::uint32_t rectangle;
    bool opens;
  };
  std::vector<Event> events;
  events.reserve(2 * rectangles.size());
  for (std::uint32_t r = 0; r < rectangles.size(); ++r) {
    events.push_back({rectangles[r].u_low, r, true});
    events.push_back({rectangles[r].u_high, r, false});
  }
  std::sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.u < b.u; });
  std::vector<std::uint32_t> active;
  std::vector<std::pair<double, double>> spans;
  double area = 0.0;
  for (std::size_t e = 0; e < events.size(); ++e) {
    if (e > 0 && events[e].u > events[e - 1].u && !active.empty()) {
      // The slab since the last event: the union of its rectangles' v-extents.
      spans.clear();
      for (const std::uint32_t r : active) spans.emplace_back(rectangles[r].v_low, rectangles[r].v_high);
      std::sort(spans.begin(), spans.end());
      double covered = 0.0;
      double low = spans[0].first;
      double high = spans[0].second;
      for (const auto& [span_low, span_high] : spans) {
        if (span_low > high) {
          covered += high - low;
          low = span_low;
        }
        high = std::max(high, span_high);
      }
      covered += high - low;
      area += covered * (events[e].u - events[e - 1].u);
    }
    if (events[e].opens) {
      active.push_back(events[e].rectangle);
    } else {
      const auto at = std::find(active.begin(), active.end(), events[e].rectangle);
      *at = active.back();
      active.pop_back();
    }
  }
  return area;
}

// A patch's fit is left to its blocks that hold one surface (kOneSurfaceSpread) where they
// hold at least this share of its points.
constexpr double kMinSingleShare = 0.5;

double square(double x) { return x * x; }

}  // namespace

double surfaceOf(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks) {
  double surface = 0.0;
  for (const std::uint32_t id : blocks) surface += grid.blocks()[id].surface;
  return surface;
}

Plane describePatch(const BlockGrid& grid, const Patch& patch, const CandidatePlane& reference, double kappa_rad,
                    double noise) {
  Plane plane;
  PcaSums pca;
  const Eigen::Vector3d origin = reference.point.cast<double>();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const std::uint32_t id : patch.blocks) {
    const PlaneBlock& block = grid.blocks()[id];
    centroid += block.point.cast<double>();
    pca.addBlock(block.point.cast<double>() - origin, block.vertical ? 0.5 * (block.top - block.bottom) : 0.0,
                 block.surface);
  }
  Eigen::Vector3d normal = reference.normal.cast<double>();
  Eigen::Vector3d point = origin;
  if (pca.weight >= 3.0) {
    const Eigen::Vector3d mean = pca.mean();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(pca.covariance());
    const Eigen::Vector3d fitted = solver.eigenvectors().col(0);
    if (solver.eigenvalues()(1) > 1e-4 && std::abs(fitted.dot(normal)) > std::cos(kappa_rad)) normal = fitted;
    point = origin + mean;
  }
  // The plane, its offset and its RMS from the patch's points where the map keeps
  // their moments (point_stats.hpp): a least-squares fit to the points themselves,
  // not to the blocks' positions, and the points' own residual.
  // A block whose points' mean lies more than 3 σ off the blocks' plane holds mostly
  // another surface's points: a stair's cell whose top reaches the upper tread while
  // most of its points lie on the lower one (the riser between them within the cell). It
  // is left out of the points' fit where enough remain. Fitted to all, the treads of a
  // staircase at 10 cm cells leaned 17-21° towards their risers and chained into one ramp
  // (tests/test_planes_stairs.cpp). 3 σ: a level block's points lie at most half its
  // depth (the level band, 5 σ) below its top.
  const double cut = noise > 0.0 ? 3.0 * noise : std::numeric_limits<double>::infinity();
  std::vector<PointStats> stats(patch.blocks.size());
  std::vector<Eigen::Vector3d> centres(patch.blocks.size());
  std::vector<char> off(patch.blocks.size(), 0);
  double kept = 0.0;
  for (std::size_t k = 0; k < patch.blocks.size(); ++k) {
    const std::uint32_t id = patch.blocks[k];
    stats[k] = grid.pointsOf(id);
    centres[k] = grid.pointsFrameOf(id);
    if (stats[k].empty()) continue;
    off[k] = std::abs(normal.dot(centres[k] + stats[k].mean() - point)) > cut;
    if (!off[k]) kept += stats[k].count;
  }
  if (kept < 3.0) std::fill(off.begin(), off.end(), 0);
  PointMoments points;
  for (std::size_t k = 0; k < patch.blocks.size(); ++k) {
    if (!off[k]) points.add(stats[k], centres[k] - origin);
  }
  std::optional<double> points_rms;
  const auto fitTo = [&](const PointMoments& moments) {
    const Eigen::Matrix3d covariance = moments.covariance();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(covariance);
    const Eigen::Vector3d fitted = solver.eigenvectors().col(0);
    if (solver.eigenvalues()(1) > 1e-4 && std::abs(fitted.dot(normal)) > std::cos(kappa_rad)) normal = fitted;
    point = origin + moments.mean();
    points_rms = std::sqrt(std::max(0.0, normal.dot(covariance * normal)));
  };
  if (points.count >= 3.0) fitTo(points);
  // Then without the blocks that hold a second surface: those whose points spread along the
  // plane's normal by more than kOneSurfaceSpread σ (an edge cell holding a rim, a bevel or the
  // face below it), where the rest hold most of the points. Their points pulled the plane:
  // at 10 cm cells fr079's upper wall face leaned onto its lower face 8-10 cm in front and the
  // two were one patch, ANYmal's treads lay 0.3 cm off their points' fit (bench/real_data.py,
  // session 41). Blocks of one or two points tell nothing: PCL's room_scan2 desk at 10 cm stays
  // 6° off, a patch of such blocks.
  if (noise > 0.0 && points.count >= 3.0) {
    PointMoments single;
    bool mixed = false;
    for (std::size_t k = 0; k < patch.blocks.size(); ++k) {
      if (off[k] || stats[k].empty()) continue;
      const double dof = static_cast<double>(stats[k].count) - 1.0;
      if (dof >= 2.0 && normal.dot(stats[k].scatterMatrix() * normal) > dof * square(kOneSurfaceSpread * noise)) {
        mixed = true;
        continue;
      }
      single.add(stats[k], centres[k] - origin);
    }
    if (mixed && single.count >= 3.0 && single.count >= kMinSingleShare * points.count) fitTo(single);
  }
  normal = orientConsistently(normal.cast<float>()).cast<double>();
  plane.normal = normal;
  plane.offset = -normal.dot(point);
  plane.centroid = centroid / static_cast<double>(patch.blocks.size());
  plane.area = coveredArea(grid, patch.blocks, normal, point, std::max(patch.raster_step, spacingStep(grid, patch.blocks)));
  plane.block_count = patch.blocks.size();
  if (points_rms) {
    plane.rms = *points_rms;
  } else {
    double squared = 0.0;
    for (const std::uint32_t id : patch.blocks) {
      const double distance = normal.dot(grid.blocks()[id].point.cast<double>()) + plane.offset;
      squared += distance * distance;
    }
    plane.rms = std::sqrt(squared / static_cast<double>(patch.blocks.size()));
  }
  placeOutline(plane, patch.outline);
  return plane;
}

void placePatch(PatchSet& set, std::size_t slot, Plane plane, std::vector<std::uint32_t> blocks,
                const OutlineFrame& frame) {
  if (slot == set.planes.size()) {
    set.planes.emplace_back();
    set.blocks.emplace_back();
    set.outline_frames.emplace_back();
    set.outline_runs.emplace_back();
  }
  plane.id = static_cast<std::int32_t>(slot + 1);
  for (const std::uint32_t id : blocks) set.labels[id] = plane.id;
  set.planes[slot] = std::move(plane);
  set.blocks[slot] = std::move(blocks);
  set.outline_frames[slot] = frame;
  set.outline_runs[slot] = {};
}

void dropPatches(PatchSet& set, const std::vector<bool>& drop) {
  if (std::none_of(drop.begin(), drop.end(), [](bool d) { return d; })) return;
  const std::size_t count = set.planes.size();
  std::vector<std::int32_t> new_id(count, 0);
  PatchSet kept;
  kept.labels = std::move(set.labels);
  for (std::size_t k = 0; k < count; ++k) {
    if (drop[k]) continue;
    Plane plane = std::move(set.planes[k]);
    plane.id = static_cast<std::int32_t>(kept.planes.size() + 1);
    new_id[k] = plane.id;
    kept.planes.push_back(std::move(plane));
    kept.blocks.push_back(std::move(set.blocks[k]));
    kept.outline_frames.push_back(set.outline_frames[k]);
    kept.outline_runs.push_back(std::move(set.outline_runs[k]));
  }
  for (std::int32_t& label : kept.labels)
    if (label > 0) label = new_id[static_cast<std::size_t>(label - 1)];
  set = std::move(kept);
}

void tracePendingOutlines(const BlockGrid& grid, PatchSet& set, int threads) {
  std::vector<std::size_t> pending;
  for (std::size_t k = 0; k < set.planes.size(); ++k) {
    if (set.outline_frames[k].pending) pending.push_back(k);
  }
#ifdef _OPENMP
  const int team = threads > 0 ? threads : omp_get_max_threads();
#else
  (void)threads;
#endif
  const auto count = static_cast<std::int64_t>(pending.size());
  // Each plane into its own slot: the same outlines at any thread count. Largest
  // first in the list (the search's order), so dynamic scheduling balances them.
#pragma omp parallel for schedule(dynamic, 1) num_threads(team) if (count > 1)
  for (std::int64_t n = 0; n < count; ++n) {
    const std::size_t k = pending[static_cast<std::size_t>(n)];
    OutlineFrame& frame = set.outline_frames[k];
    std::vector<Segment>& runs = set.outline_runs[k];
    // The split's runs are on the grid's cells: a patch sampled sparser is traced again.
    const int step = std::max(frame.step, spacingStep(grid, set.blocks[k]));
    if (runs.empty() || step > 1) runs = runsOf(grid, set.blocks[k], frame.normal, frame.point, step);
    const double raster_cell = grid.cellSize() * step;
    placeOutline(set.planes[k], outlineOfRuns(runs, raster_cell, frame.normal, frame.point),
                 cornersOfRuns(runs, raster_cell, frame.normal, frame.point));
    frame.pending = false;
    runs = {};
  }
}

}  // namespace mlmap
