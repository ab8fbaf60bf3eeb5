#include "patch_rules.hpp"

#include "mlmap/planes/classify.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "id_set.hpp"
#include "median.hpp"
#include "pca_sums.hpp"

namespace mlmap {
namespace {

// Sums over a plane's blocks run in chunks of this many: on several threads for a
// floor's 150 000, and chunk by chunk in order whatever the thread count.
constexpr std::size_t kChunk = 8192;

// The sums of add(sums, n) over n < count, taken chunk by chunk and the chunks'
// sums combined in order: the same result at any thread count.
template <typename Sums, typename Add, typename Combine>
Sums sumInChunks(std::size_t count, [[maybe_unused]] int threads, Add add, Combine combine) {
  const std::size_t chunks = (count + kChunk - 1) / kChunk;
  std::vector<Sums> partial(chunks);
  const auto chunk_count = static_cast<std::int64_t>(chunks);
#pragma omp parallel for schedule(static) num_threads(std::max(threads, 1)) if (threads > 1 && chunks > 1)
  for (std::int64_t chunk = 0; chunk < chunk_count; ++chunk) {
    const std::size_t end = std::min(count, static_cast<std::size_t>(chunk + 1) * kChunk);
    for (std::size_t n = static_cast<std::size_t>(chunk) * kChunk; n < end; ++n) {
      add(partial[static_cast<std::size_t>(chunk)], n);
    }
  }
  Sums total{};
  for (const Sums& sums : partial) combine(total, sums);
  return total;
}

}  // namespace

std::vector<std::uint32_t> withEdges(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                                     const PlaneScorer& scorer, std::vector<std::uint32_t> matching,
                                     const CandidatePlane& plane, double epsilon, double kappa_rad) {
  const float cos_edge = edgeCosine(kappa_rad);
  const auto reach = static_cast<float>(epsilon);
  IdSet in_plane(grid.size());
  for (const std::uint32_t id : matching) in_plane.insert(id);
  // The blocks that may join, from the scorer's index: a few edges and strays, where a
  // ring round every matching block visits a floor's 150 000 blocks and the ceiling's.
  IdSet joinable(grid.size());
  std::vector<std::uint32_t> frontier;
  for (const std::uint32_t id : scorer.near(plane, cos_edge, reach)) {
    if (in_plane.contains(id)) continue;
    const Eigen::Vector3f& direction = directions[id];
    if (direction.squaredNorm() > 0.0F && std::abs(direction.dot(plane.normal)) < cos_edge) continue;
    if (std::abs(plane.normal.dot(grid.blocks()[id].point - plane.point)) >= reach) continue;
    joinable.insert(id);
    bool touches = false;
    grid.forEachNeighbour(grid.blocks()[id].cell, 1, [&](std::uint32_t other) { touches = touches || in_plane.contains(other); });
    if (touches) frontier.push_back(id);
  }
  // They join when they touch the plane's blocks, or blocks that joined.
  for (const std::uint32_t id : frontier) in_plane.insert(id);
  while (!frontier.empty()) {
    std::vector<std::uint32_t> next;
    for (const std::uint32_t id : frontier) {
      grid.forEachNeighbour(grid.blocks()[id].cell, 1, [&](std::uint32_t other) {
        if (!joinable.contains(other) || in_plane.contains(other)) return;
        in_plane.insert(other);
        next.push_back(other);
      });
    }
    frontier = std::move(next);
  }
  return in_plane.ascending();
}

double directionSpread(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                       const std::vector<std::uint32_t>& ids, const CandidatePlane& plane) {
  double weighted = 0.0;
  double weight = 0.0;
  for (const std::uint32_t id : ids) {
    const double cosine = std::min(1.0F, std::abs(directions[id].dot(plane.normal)));
    weighted += grid.blocks()[id].surface * std::acos(cosine);
    weight += grid.blocks()[id].surface;
  }
  return weight > 0.0 ? weighted / weight * 180.0 / std::numbers::pi : 0.0;
}

std::size_t fitPoints(const BlockGrid& grid, const Patch& patch) {
  std::size_t points = 0;
  for (const std::uint32_t id : patch.blocks) points += grid.blocks()[id].vertical ? 2 : 1;
  return points;
}

double medianDistance(const BlockGrid& grid, const std::vector<std::uint32_t>& ids, const CandidatePlane& plane) {
  if (ids.empty()) return 0.0;
  std::vector<float> distances;
  distances.reserve(ids.size());
  for (const std::uint32_t id : ids) distances.push_back(std::abs(plane.normal.dot(grid.blocks()[id].point - plane.point)));
  return medianOf(distances);
}

double noiseSpread(const std::vector<float>& tilts, const std::vector<std::uint32_t>& ids, double kappa_rad) {
  std::vector<float> known;
  known.reserve(ids.size());
  for (const std::uint32_t id : ids) {
    if (std::isfinite(tilts[id])) known.push_back(std::min(tilts[id], static_cast<float>(kappa_rad)));
  }
  if (known.empty()) return 0.0;
  return medianOf(known) * std::sqrt(std::numbers::pi / 2.0) * 180.0 / std::numbers::pi;
}

bool spreadExceeds(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                   const std::vector<std::uint32_t>& ids, const CandidatePlane& plane, double max_deg, int threads) {
  // An angle θ = acos c of [0, π/2] lies between sin θ and tan θ: with s = √(1 − c²),
  // s ≤ θ ≤ s / c, bounds 1 / c apart (a part in 6 000 at 1°, 1 % at 8°), where the
  // blocks of a plane mostly lie within a few degrees of its normal. The weights are
  // directionSpread's, so its value lies between the two bounds' up to rounding (parts
  // in 10¹⁰ for a million blocks), far inside the margin.
  constexpr double kMargin = 1e-7;
  struct Bounds {
    double lower = 0.0;
    double upper = 0.0;
    double weight = 0.0;
  };
  const Bounds total = sumInChunks<Bounds>(
      ids.size(), threads,
      [&](Bounds& bounds, std::size_t n) {
        const std::uint32_t id = ids[n];
        const double cosine = std::min(1.0F, std::abs(directions[id].dot(plane.normal)));
        const double sine = std::sqrt(std::max(0.0, 1.0 - cosine * cosine));
        const double surface = grid.blocks()[id].surface;
        bounds.lower += surface * sine;
        bounds.upper += surface * (sine / cosine);
        bounds.weight += surface;
      },
      [](Bounds& total_bounds, const Bounds& bounds) {
        total_bounds.lower += bounds.lower;
        total_bounds.upper += bounds.upper;
        total_bounds.weight += bounds.weight;
      });
  if (!(total.weight > 0.0)) return directionSpread(grid, directions, ids, plane) > max_deg;
  const double degrees = 180.0 / std::numbers::pi;
  if (total.lower / total.weight * degrees > max_deg * (1.0 + kMargin)) return true;
  if (total.upper / total.weight * degrees < max_deg * (1.0 - kMargin)) return false;
  return directionSpread(grid, directions, ids, plane) > max_deg;
}

bool isThin(const BlockGrid& grid, const Patch& patch, const CandidatePlane& plane, double min_width, int threads) {
  const PcaSums pca = sumInChunks<PcaSums>(
      patch.blocks.size(), threads,
      [&](PcaSums& sums, std::size_t n) {
        const PlaneBlock& block = grid.blocks()[patch.blocks[n]];
        sums.addBlock((block.point - plane.point).cast<double>(),
                      block.vertical ? 0.5 * (block.top - block.bottom) : 0.0, 1.0);
      },
      [](PcaSums& total, const PcaSums& sums) { total.addShifted(sums, Eigen::Vector3d::Zero()); });
  // The spread across the plane: the covariance in the plane's own basis.
  Eigen::Vector3d u_axis;
  Eigen::Vector3d v_axis;
  planeBasis(plane.normal.cast<double>(), u_axis, v_axis);
  Eigen::Matrix<double, 3, 2> basis;
  basis << u_axis, v_axis;
  const Eigen::Matrix2d in_plane = basis.transpose() * pca.covariance() * basis;
  const ClassifyConfig classes;
  if (isPlumb(plane.normal.cast<double>(), classes)) {
    // A wall's face: one cell wide along the wall it is a fringe or a line of clutter, but
    // its height is its points' own, not a count of cells. Here a block counts its top and
    // bottom, half its depth either side: a riser of 14-17 cm spreads 7-8.5 cm, about 0.7
    // of a 10 cm cell, and the width rule refused risers at 10 cm cells (the simulated
    // corridor's) and at 5 cm where a riser shows only 5-9 cm of itself (the far risers of a
    // stairwell seen from 0.3 m). Up a wall the least is now the lowest riser's
    // (ClassifyConfig::riser_min, 8 cm) with its points spread evenly up it, 8 / √12 =
    // 2.3 cm: a face of one block 4.6 cm deep or more.
    const double along = std::sqrt(std::max(0.0, in_plane(0, 0)));
    const double up = std::sqrt(std::max(0.0, in_plane(1, 1)));
    return along < min_width || up < classes.riser_min / std::sqrt(12.0);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(in_plane);
  const double minor = std::sqrt(std::max(0.0, solver.eigenvalues()(0)));
  return minor < min_width;
}

}  // namespace mlmap
