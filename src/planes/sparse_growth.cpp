#include "sparse_growth.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <iterator>
#include <numbers>
#include <optional>
#include <unordered_map>
#include <utility>

#include "floor_divide.hpp"
#include "id_set.hpp"
#include "patch_rules.hpp"
#include "seen_gaps.hpp"

namespace mlmap {
namespace {

// m: how far a wall looks either side for what was seen through an opening (as
// joinUnseenGaps: a doorway shows the floor beyond it).
constexpr double kOpeningReach = 0.3;

// m: the widest gap a patch grows across, whatever it is configured with.
constexpr double kMaxGap = 10.0;

struct GrowthPlane {
  Eigen::Vector3d normal;
  Eigen::Vector3d point;
  double epsilon = 0.0;
  bool level = false;
  bool seen_from_above = false;  // level: what lies past it is below (a floor, a table), else above (a ceiling)
};

// m: the gap between two blocks on the plane: across (their points, in the plane) and,
// on a wall, up (between their extents: a wall block is tall).
double gapBetween(const PlaneBlock& a, const PlaneBlock& b, const GrowthPlane& plane) {
  Eigen::Vector3d step = (b.point - a.point).cast<double>();
  step -= plane.normal * plane.normal.dot(step);
  if (plane.level) return step.norm();
  const double vertical = std::max({0.0, static_cast<double>(b.bottom - a.top), static_cast<double>(a.bottom - b.top)});
  return std::hypot(std::hypot(step.x(), step.y()), vertical);
}

// Whether the cells strictly between two blocks' cells show that the scanner saw past the
// plane there: a level plane's far side (seenPast), or a wall's both sides (an opening).
bool seenPastBetween(const BlockGrid& grid, const GrowthPlane& plane, CellIndex from, CellIndex to) {
  if (plane.level) {
    return seenPast(grid, plane.normal, plane.point, from, to, plane.epsilon,
                    plane.seen_from_above ? FarSide::Below : FarSide::Above);
  }
  bool front = false;
  bool behind = false;
  return anyCellBetween(from, to, [&](CellIndex cell) {
    grid.forEachInCells(cell.i, cell.i, cell.j, cell.j, [&](std::uint32_t id) {
      const double distance = plane.normal.dot(grid.blocks()[id].point.cast<double>() - plane.point);
      if (std::abs(distance) <= plane.epsilon || std::abs(distance) > kOpeningReach) return;
      (distance > 0.0 ? front : behind) = true;
    });
    return front && behind;
  });
}

}  // namespace

bool levelOrPlumb(const Eigen::Vector3d& normal, double max_tilt_rad) {
  const double tilt = std::acos(std::min(1.0, std::abs(normal.z())));
  return std::min(tilt, std::numbers::pi / 2 - tilt) <= max_tilt_rad;
}

bool isWallRung(const BlockGrid& grid, std::uint32_t id, double ladder_gap) {
  const PlaneBlock& block = grid.blocks()[id];
  bool rung = false;
  grid.forEachInCells(block.cell.i, block.cell.i, block.cell.j, block.cell.j, [&](std::uint32_t other) {
    if (other == id) return;
    const PlaneBlock& near = grid.blocks()[other];
    rung = rung || (near.bottom < block.top + ladder_gap && near.top > block.bottom - ladder_gap);
  });
  return rung;
}

std::vector<std::uint32_t> sparseGrowth(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                                        const std::vector<std::uint32_t>& candidates,
                                        const std::vector<std::uint32_t>& patch, const CandidatePlane& reference,
                                        double epsilon, const SparseGrowth& config) {
  if (!(config.max_gap > 0.0) || candidates.empty() || patch.empty()) return {};
  // Only level and plumb planes: a tilted plane through sparse blocks is as likely the
  // envelope of a staircase's nosings (fr079's stair at 10 cm cells, 23°) as a ramp, and
  // grown it took every tread within its ε.
  if (!levelOrPlumb(reference.normal.normalized().cast<double>(), config.max_tilt_rad)) return {};
  GrowthPlane plane{reference.normal.cast<double>().normalized(), reference.point.cast<double>(), epsilon,
                    std::abs(reference.normal.z()) >= std::cos(std::numbers::pi / 4.0), false};
  const float cos_edge = edgeCosine(config.kappa_rad);
  IdSet pool(grid.size());
  std::size_t pooled = 0;
  for (const std::uint32_t id : candidates) {
    const PlaneBlock& block = grid.blocks()[id];
    // A level plane takes level blocks only, and no short block with another of its cell
    // less than a ladder gap above or below: that is a rung of a wall seen from afar (fr079
    // at 5 cm: a table's plane took 96 points of the wall beside it).
    if (plane.level && (block.vertical || isWallRung(grid, id, config.ladder_gap))) continue;
    const Eigen::Vector3f& direction = directions[id];
    if (direction.squaredNorm() > 0.0F && std::abs(direction.dot(reference.normal)) < cos_edge) continue;
    if (std::abs(plane.normal.dot(block.point.cast<double>() - plane.point)) >= epsilon) continue;
    pool.insert(id);
    ++pooled;
  }
  if (pooled == 0) return {};
  if (plane.level) {
    // A majority over at most 4096 of its blocks, evenly spread: a floor at 2 cm has
    // 150 000, and asking each of them cost more than the growth itself.
    const std::size_t stride = std::max<std::size_t>(1, patch.size() / 4096);
    std::vector<std::uint32_t> sample;
    sample.reserve(patch.size() / stride + 1);
    for (std::size_t k = 0; k < patch.size(); k += stride) sample.push_back(patch[k]);
    plane.seen_from_above = seenFromAbove(grid, sample, plane.normal, plane.point, epsilon);
  }
  IdSet inside(grid.size());
  for (const std::uint32_t id : patch) inside.insert(id);
  // At most kMaxGap (a configuration read from a file is not bounded as the CLI's is).
  const double max_gap = std::min(config.max_gap, kMaxGap);
  const int reach = static_cast<int>(std::ceil(max_gap / grid.cellSize()));
  IdSet joined(grid.size());
  std::deque<std::uint32_t> queue;
  // The patch block nearest to `block` within `radius` cells and max_gap, if any.
  const auto nearestInside = [&](const PlaneBlock& block, int radius) -> std::optional<std::uint32_t> {
    double nearest = max_gap;
    std::optional<std::uint32_t> from;
    grid.forEachNeighbour(block.cell, radius, [&](std::uint32_t other) {
      if (!inside.contains(other)) return;
      const double gap = gapBetween(grid.blocks()[other], block, plane);
      if (gap <= nearest) {
        nearest = gap;
        from = other;
      }
    });
    return from;
  };
  // From the patch: each candidate by its nearest patch block, looked for next to it
  // first (most candidates are the patch's own edges: a window of max_gap over a 2 cm
  // floor holds thousands of blocks), then within max_gap.
  const int near_radius = std::min(reach, 2);
  for (const std::uint32_t id : candidates) {
    if (!pool.contains(id)) continue;
    const PlaneBlock& block = grid.blocks()[id];
    std::optional<std::uint32_t> from = nearestInside(block, near_radius);
    if (!from && reach > near_radius) from = nearestInside(block, reach);
    if (from && !seenPastBetween(grid, plane, grid.blocks()[*from].cell, block.cell)) {
      joined.insert(id);
      queue.push_back(id);
    }
  }
  // Then block by block from those that joined, among the candidates only: they are
  // bucketed by squares of max_gap, so a step looks at nine buckets, not at every block
  // within max_gap.
  const auto bucket_of = [reach](CellIndex cell) {
    return std::pair<std::int64_t, std::int64_t>{floorDivide(cell.i, reach), floorDivide(cell.j, reach)};
  };
  const auto key_of = [](std::int64_t bi, std::int64_t bj) { return (bi << 32) ^ (bj & 0xffffffffLL); };
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> buckets;
  for (const std::uint32_t id : candidates) {
    if (!pool.contains(id) || joined.contains(id)) continue;
    const auto [bi, bj] = bucket_of(grid.blocks()[id].cell);
    buckets[key_of(bi, bj)].push_back(id);
  }
  while (!queue.empty() && !buckets.empty()) {
    const std::uint32_t id = queue.front();
    queue.pop_front();
    const PlaneBlock& block = grid.blocks()[id];
    const auto [bi, bj] = bucket_of(block.cell);
    for (std::int64_t di = -1; di <= 1; ++di) {
      for (std::int64_t dj = -1; dj <= 1; ++dj) {
        const auto found = buckets.find(key_of(bi + di, bj + dj));
        if (found == buckets.end()) continue;
        for (const std::uint32_t other : found->second) {
          if (joined.contains(other)) continue;
          const PlaneBlock& next = grid.blocks()[other];
          if (gapBetween(block, next, plane) > max_gap || seenPastBetween(grid, plane, block.cell, next.cell)) {
            continue;
          }
          joined.insert(other);
          queue.push_back(other);
        }
      }
    }
  }
  return joined.ascending();
}

void growPatches(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions, const PlaneScorer& scorer,
                 const std::vector<CandidatePlane>& references, std::vector<double>& surfaces, PatchSet& set,
                 const SparseGrowth& config, std::size_t first) {
  const float cos_edge = edgeCosine(config.kappa_rad);
  for (std::size_t k = first; k < set.planes.size(); ++k) {
    const CandidatePlane& reference = references[k];
    const float band = scorer.bandOf(reference);
    // The untaken blocks within the band, matching or not (ascending), but those an
    // earlier patch grew into.
    std::vector<std::uint32_t> candidates = scorer.near(reference, cos_edge, band, true);
    std::erase_if(candidates, [&](std::uint32_t id) { return set.labels[id] != 0; });
    const std::vector<std::uint32_t> grown =
        sparseGrowth(grid, directions, candidates, set.blocks[k], reference, band, config);
    if (grown.empty()) continue;
    for (const std::uint32_t block : grown) {
      set.labels[block] = set.planes[k].id;
      surfaces[k] += grid.blocks()[block].surface;
    }
    std::vector<std::uint32_t> blocks;
    blocks.reserve(set.blocks[k].size() + grown.size());
    std::merge(set.blocks[k].begin(), set.blocks[k].end(), grown.begin(), grown.end(), std::back_inserter(blocks));
    set.blocks[k] = std::move(blocks);
    set.outline_runs[k].clear();
  }
}

}  // namespace mlmap
