#include "patch_set.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "mlmap/planes/direction_vectors.hpp"
#include "median.hpp"
#include "pca_sums.hpp"
#include "raster_frame.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap {
namespace {

// Merges the planes that share a root (the root's index is the smallest of its
// group); ids are renumbered in order and the block labels follow.
void mergeGroups(const BlockGrid& grid, PatchSet& set, const std::vector<std::size_t>& roots, double kappa_rad,
                 double noise) {
  const std::vector<Plane>& planes = set.planes;
  const std::size_t count = planes.size();
  std::vector<Plane> merged;
  std::vector<std::vector<std::uint32_t>> merged_blocks;
  std::vector<OutlineFrame> merged_frames;
  std::vector<std::vector<Segment>> merged_runs;
  std::vector<std::int32_t> new_id(count, 0);
  for (std::size_t k = 0; k < count; ++k) {
    if (roots[k] != k) continue;
    std::size_t members = 0;
    for (std::size_t member = 0; member < count; ++member) members += roots[member] == k ? 1 : 0;
    Plane plane;
    Patch patch;
    OutlineFrame frame;
    std::vector<Segment> runs;
    if (members == 1) {
      plane = planes[k];  // alone: as it was
      patch.blocks = std::move(set.blocks[k]);
      frame = set.outline_frames[k];
      runs = std::move(set.outline_runs[k]);
    } else {
      // Each member's blocks are ascending: merged, not sorted again.
      for (std::size_t member = 0; member < count; ++member) {
        if (roots[member] != k) continue;
        const auto middle = static_cast<std::ptrdiff_t>(patch.blocks.size());
        patch.blocks.insert(patch.blocks.end(), set.blocks[member].begin(), set.blocks[member].end());
        std::inplace_merge(patch.blocks.begin(), patch.blocks.begin() + middle, patch.blocks.end());
      }
      const Plane& largest = planes[k];
      const CandidatePlane reference{largest.normal.cast<float>(), largest.centroid.cast<float>()};
      for (const std::uint32_t id : patch.blocks) patch.surface += grid.blocks()[id].surface;
      frame = OutlineFrame{largest.normal, largest.centroid, true};
      plane = describePatch(grid, patch, reference, kappa_rad, noise);
      plane.source = largest.source;
      plane.candidates = largest.candidates;
      plane.label = largest.label;
    }
    plane.id = static_cast<std::int32_t>(merged.size() + 1);
    for (std::size_t member = 0; member < count; ++member) {
      if (roots[member] == k) new_id[member] = plane.id;
    }
    merged.push_back(std::move(plane));
    merged_blocks.push_back(std::move(patch.blocks));
    merged_frames.push_back(frame);
    merged_runs.push_back(std::move(runs));
  }
  set.planes = std::move(merged);
  set.blocks = std::move(merged_blocks);
  set.outline_frames = std::move(merged_frames);
  set.outline_runs = std::move(merged_runs);
  for (std::int32_t& label : set.labels) {
    if (label > 0) label = new_id[static_cast<std::size_t>(label - 1)];
  }
}

// A patch's points' moments about `origin` (a map's cell centre at z 0): patches' moments
// about one origin add up to their union's.
PointMoments patchMoments(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& origin) {
  PointMoments points;
  for (const std::uint32_t id : blocks) {
    points.add(grid.pointsOf(id), (Eigen::Vector3d() << grid.cellCentre(grid.blocks()[id].cell), 0.0).finished() - origin);
  }
  return points;
}

// The RMS distance of points from their least-squares plane; nullopt for fewer than 3.
std::optional<double> planeRms(const PointMoments& points) {
  if (points.count < 3.0) return std::nullopt;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(points.covariance(), Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, solver.eigenvalues()(0)));
}

// The outline lies on the plane the patch was split on: put it on the patch's own.
void placeOutline(Plane& plane, const std::vector<Eigen::Vector3d>& corners) {
  plane.outline.clear();
  for (const Eigen::Vector3d& corner : corners) {
    plane.outline.push_back(corner - plane.normal * (plane.normal.dot(corner) + plane.offset));
  }
}

// The area the blocks cover on the plane, not their surface: a wall on a cell boundary
// has blocks in both cell columns, each of the wall's full height, and a wall at 45°
// crosses √2 cells per cell of its length. Each block stands for its cell: on a level
// plane the cells are counted (over |n_z| for its slope); on any other its cell's
// extent along the plane's level axis u times its own extent up the plane (v) is a
// rectangle, and the area of the rectangles' union is swept along u.
double coveredArea(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
                   const Eigen::Vector3d& point) {
  const double cell = grid.cellSize();
  if (blocks.empty()) return 0.0;
  if (Eigen::Vector3d::UnitZ().cross(normal).norm() < RasterFrame::kLevelSine) {
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

struct CellBox {
  std::int32_t min_i = std::numeric_limits<std::int32_t>::max();
  std::int32_t max_i = std::numeric_limits<std::int32_t>::min();
  std::int32_t min_j = std::numeric_limits<std::int32_t>::max();
  std::int32_t max_j = std::numeric_limits<std::int32_t>::min();
};

}  // namespace

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
    centres[k] = (Eigen::Vector3d() << grid.cellCentre(grid.blocks()[id].cell), 0.0).finished();
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
  if (points.count >= 3.0) {
    const Eigen::Matrix3d covariance = points.covariance();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(covariance);
    const Eigen::Vector3d fitted = solver.eigenvectors().col(0);
    if (solver.eigenvalues()(1) > 1e-4 && std::abs(fitted.dot(normal)) > std::cos(kappa_rad)) normal = fitted;
    point = origin + points.mean();
    points_rms = std::sqrt(std::max(0.0, normal.dot(covariance * normal)));
  }
  normal = orientConsistently(normal.cast<float>()).cast<double>();
  plane.normal = normal;
  plane.offset = -normal.dot(point);
  plane.centroid = centroid / static_cast<double>(patch.blocks.size());
  plane.area = coveredArea(grid, patch.blocks, normal, point);
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
    placeOutline(set.planes[k], runs.empty() ? outlineOf(grid, set.blocks[k], frame.normal, frame.point)
                                             : outlineOfRuns(runs, grid.cellSize(), frame.normal, frame.point));
    frame.pending = false;
    runs = {};
  }
}

void mergeCoplanar(const BlockGrid& grid, PatchSet& set, double epsilon, double kappa_rad, double noise) {
  const std::vector<Plane>& planes = set.planes;
  const std::size_t count = planes.size();
  std::vector<std::size_t> group(count);
  for (std::size_t k = 0; k < count; ++k) group[k] = k;
  auto root = [&](std::size_t k) {
    while (group[k] != k) k = group[k] = group[group[k]];
    return k;
  };
  const double cos_parallel = std::cos(0.5 * kappa_rad);
  // Each patch's points' moments, summed once when a pair first needs them.
  std::vector<std::optional<PointMoments>> moments(count);
  const Eigen::Vector3d origin =
      grid.size() > 0 ? (Eigen::Vector3d() << grid.cellCentre(grid.blocks().front().cell), 0.0).finished()
                      : Eigen::Vector3d::Zero();
  const auto level = [](const Plane& plane) { return std::abs(plane.normal.z()) >= std::cos(std::numbers::pi / 4.0); };
  // Pieces closer than a table leg's width are one surface.
  const int touch_radius = std::max(2, static_cast<int>(std::ceil(0.3 / grid.cellSize())));
  std::vector<CellBox> boxes(count);
  for (std::size_t k = 0; k < count; ++k) {
    for (const std::uint32_t id : set.blocks[k]) {
      const CellIndex cell = grid.blocks()[id].cell;
      boxes[k].min_i = std::min(boxes[k].min_i, cell.i);
      boxes[k].max_i = std::max(boxes[k].max_i, cell.i);
      boxes[k].min_j = std::min(boxes[k].min_j, cell.j);
      boxes[k].max_j = std::max(boxes[k].max_j, cell.j);
    }
  }
  for (std::size_t a = 0; a < count; ++a) {
    for (std::size_t b = a + 1; b < count; ++b) {
      const Plane& first = planes[a];
      const Plane& second = planes[b];
      if (std::abs(first.normal.dot(second.normal)) < cos_parallel) continue;
      // The smaller piece lies on the larger one's plane: its own fit is the less sure
      // (a few blocks' tilt puts the far centroid of a long wall well off it).
      const bool first_larger = set.blocks[a].size() >= set.blocks[b].size();
      const Plane& larger = first_larger ? first : second;
      const Plane& smaller = first_larger ? second : first;
      if (std::abs(larger.normal.dot(smaller.centroid) + larger.offset) >= epsilon) continue;
      if (boxes[a].min_i - touch_radius > boxes[b].max_i || boxes[b].min_i - touch_radius > boxes[a].max_i ||
          boxes[a].min_j - touch_radius > boxes[b].max_j || boxes[b].min_j - touch_radius > boxes[a].max_j) {
        continue;
      }
      // Walk the smaller patch's neighbourhood looking for the larger one's label.
      const bool a_smaller = set.blocks[a].size() <= set.blocks[b].size();
      const auto& walked = set.blocks[a_smaller ? a : b];
      const std::int32_t wanted = (a_smaller ? second : first).id;
      bool touching = false;
      for (const std::uint32_t id : walked) {
        grid.forEachNeighbour(grid.blocks()[id].cell, touch_radius, [&](std::uint32_t other) {
          if (set.labels[other] == wanted) touching = true;
        });
        if (touching) break;
      }
      // Level pieces that meet cell to cell meet at one height: stair treads, each
      // fitted leaning towards its risers, pass the tests above at 10 cm cells (plane_seg's
      // ANYmal stairs: 8-19° off level) and chained into one ramp, though where they meet
      // their blocks differ by a riser (16.5 cm).
      if (touching && level(first) && level(second)) {
        std::vector<float> seam;
        for (const std::uint32_t id : walked) {
          const PlaneBlock& block = grid.blocks()[id];
          grid.forEachNeighbour(block.cell, 1, [&](std::uint32_t other) {
            if (set.labels[other] == wanted) seam.push_back(std::abs(grid.blocks()[other].point.z() - block.point.z()));
          });
        }
        if (!seam.empty() && medianOf(seam) > epsilon) touching = false;
      }
      // Two layers are one surface only within a sheet's step (3 √2 σ, sheets.hpp) of
      // each other: pieces that far apart, each a share w of the points, add at most
      // w (1 − w) step² ≤ step² / 4 to the larger's squared RMS about a joint plane. Further
      // apart they are two surfaces: OctoMap's fr079 at 10 cm cells, two walls 7 cm apart
      // (0.7 and 1.0 cm RMS, 3.5 cm together, σ 1.3 cm) were one. Layers of one surface stay
      // one: PCL's office1's far wall (a depth camera's steps, 0 and 2-2.5 cm RMS, σ 2 cm),
      // Bobkov's table (registered views, 2.3 and 3.3 cm, σ 1.9 cm). σ is the map's median;
      // where the pieces' own RMS is larger it speaks for their surface (the simulated lab at
      // 10 cm cells: walls 1 cm, σ read 0.4 cm).
      if (touching && noise > 0.0) {
        const auto momentsOf = [&](std::size_t k) -> const PointMoments& {
          if (!moments[k]) moments[k] = patchMoments(grid, set.blocks[k], origin);
          return *moments[k];
        };
        PointMoments both = momentsOf(a);
        both.count += momentsOf(b).count;
        both.sum += momentsOf(b).sum;
        both.outer += momentsOf(b).outer;
        const std::optional<double> joint = planeRms(both);
        const double own = std::max(first.rms, second.rms);
        const double half_step = 1.5 * std::numbers::sqrt2 * std::max(noise, own);
        touching = !joint || *joint <= std::hypot(own, half_step);
      }
      if (touching) group[root(b)] = root(a);
    }
  }
  std::vector<std::size_t> roots(count);
  for (std::size_t k = 0; k < count; ++k) roots[k] = root(k);
  mergeGroups(grid, set, roots, kappa_rad, noise);
}

void mergeLevels(const BlockGrid& grid, PatchSet& set, double kappa_rad, double noise) {
  const std::vector<Plane>& planes = set.planes;
  std::vector<std::size_t> roots(planes.size());
  for (std::size_t k = 0; k < planes.size(); ++k) {
    roots[k] = k;
    if (planes[k].label != PlaneClass::Floor && planes[k].label != PlaneClass::Ceiling) continue;
    for (std::size_t first = 0; first < k; ++first) {
      if (planes[first].label == planes[k].label) {
        roots[k] = first;
        break;
      }
    }
  }
  mergeGroups(grid, set, roots, kappa_rad, noise);
}

}  // namespace mlmap
