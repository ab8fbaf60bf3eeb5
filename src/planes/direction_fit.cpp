#include "direction_fit.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

namespace mlmap {
namespace {

// The mean direction must lie this many standard errors of itself from the normal ... (3
// turned room_scan2's walls too, and lost Bobkov's wall x4.72 at 5 cm cells, 93 -> 69 %:
// a bent wall, two faces 7° apart; 6 left room_scan2's leaning plane, 4.3 standard errors)
constexpr double kTurnStandardErrors = 4.0;
// ... and at least this far (1°, in radians): turns under it move a 5 m wall's ends by less
// than 4.4 cm, inside ε, and the fit's lean is then no loss.
constexpr double kMinTurn = std::numbers::pi / 180.0;

// The plane along `direction` through the ε-wide layer of `strict` that holds the most surface.
CandidatePlane throughDensestLayer(const BlockGrid& grid, const PlaneScorer& scorer, const std::vector<std::uint32_t>& strict,
                                   const CandidatePlane& plane, const Eigen::Vector3d& direction) {
  std::vector<std::pair<double, double>> offsets;  // (offset along the direction, surface)
  offsets.reserve(strict.size());
  for (const std::uint32_t id : strict)
    offsets.emplace_back(direction.dot(grid.blocks()[id].point.cast<double>()), grid.blocks()[id].surface);
  std::sort(offsets.begin(), offsets.end());
  const double width = scorer.bandOf(plane);
  double best = -1.0, best_offset = 0.0, in_window = 0.0, weighted = 0.0;
  for (std::size_t first = 0, last = 0; last < offsets.size(); ++last) {
    in_window += offsets[last].second;
    weighted += offsets[last].second * offsets[last].first;
    while (offsets[last].first - offsets[first].first > width) {
      in_window -= offsets[first].second;
      weighted -= offsets[first].second * offsets[first].first;
      ++first;
    }
    if (in_window > best) {
      best = in_window;
      best_offset = weighted / in_window;
    }
  }
  const Eigen::Vector3d point = plane.point.cast<double>();
  CandidatePlane turned = plane;
  turned.normal = direction.cast<float>();
  turned.point = (point + (best_offset - direction.dot(point)) * direction).cast<float>();
  return turned;
}

// The blocks' mean direction (surface-weighted, each oriented along `axis`) and whether it
// lies further from `axis` than kTurnStandardErrors standard errors of itself and kMinTurn.
// The standard error: the blocks' RMS angle from the axis over the root of their effective
// number.
template <int N>
std::optional<Eigen::Matrix<double, N, 1>> significantMean(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                                                           const std::vector<std::uint32_t>& strict,
                                                           const Eigen::Matrix<double, N, 1>& axis) {
  Eigen::Matrix<double, N, 1> sum = Eigen::Matrix<double, N, 1>::Zero();
  double weight = 0.0, weight_sq = 0.0, sine_sq = 0.0;
  for (const std::uint32_t id : strict) {
    Eigen::Matrix<double, N, 1> d = directions[id].head<N>().template cast<double>();
    // Blocks without a direction, and in the level plane those whose direction points up
    // (a wall's top, a sill): no heading.
    if (!(d.squaredNorm() > 0.5)) continue;
    d.normalize();
    if (d.dot(axis) < 0.0) d = -d;
    const double w = grid.blocks()[id].surface;
    sum += w * d;
    weight += w;
    weight_sq += w * w;
    sine_sq += w * std::max(0.0, 1.0 - d.dot(axis) * d.dot(axis));
  }
  if (!(weight > 0.0) || sum.norm() < 1e-9) return std::nullopt;
  const Eigen::Matrix<double, N, 1> mean = sum.normalized();
  const double turn = std::acos(std::clamp(mean.dot(axis), -1.0, 1.0));
  const double standard_error = std::sqrt(sine_sq / weight) / std::sqrt(weight * weight / weight_sq);
  if (turn < std::max(kMinTurn, kTurnStandardErrors * standard_error)) return std::nullopt;
  return mean;
}

}  // namespace

std::optional<CandidatePlane> alongDirections(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                                              const PlaneScorer& scorer, const std::vector<std::uint32_t>& strict,
                                              const CandidatePlane& plane, double max_tilt_rad) {
  const Eigen::Vector3d normal = plane.normal.cast<double>();
  if (std::abs(normal.z()) > std::sin(max_tilt_rad)) return std::nullopt;
  // A vertical block's direction is its wall line's normal in the level plane
  // (direction_vectors.cpp), blind to how far the wall leans: it testifies to the plane's
  // heading, and to its lean only as far as walls are plumb. So two turns: (a) to the
  // blocks' heading at the plane's own lean, where the headings differ; (b) onto the
  // blocks' mean direction in 3-D (plumb for walls' blocks), where those differ, and only
  // where that holds more surface than the plane: a plane leaning between two layers
  // stacked one over the other is turned plumb, a wall that truly leans keeps its lean
  // (turned plumb, its top is left beyond ε: PCL's room_scan2, whose scanner stood 1.7°
  // off level, has a wall leaning 2.3° by its points' own fit; a generated wall leaning
  // 2.3° was turned 2.1-2.3°, its top 10 cm off the turned plane at 2.4 m). Where both
  // apply, the one that holds more.
  std::optional<CandidatePlane> best;
  if (const auto heading = significantMean<2>(grid, directions, strict, Eigen::Vector2d(normal.head<2>().normalized()))) {
    const double level_part = std::sqrt(std::max(0.0, 1.0 - normal.z() * normal.z()));
    const Eigen::Vector3d kept(level_part * heading->x(), level_part * heading->y(), normal.z());
    best = throughDensestLayer(grid, scorer, strict, plane, kept);
  }
  if (const auto mean = significantMean<3>(grid, directions, strict, normal)) {
    const CandidatePlane turned = throughDensestLayer(grid, scorer, strict, plane, *mean);
    const double rival = std::max(best ? scorer.score(*best).score : 0.0, scorer.score(plane).score);
    if (scorer.score(turned).score > rival) best = turned;
  }
  return best;
}

}  // namespace mlmap
