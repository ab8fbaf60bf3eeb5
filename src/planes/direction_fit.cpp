#include "direction_fit.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

namespace mlmap {
namespace {

// The mean direction must lie this many standard errors of itself from the normal ... (3
// turned room_scan2's walls too, and lost Bobkov's wall x4.72 at 5 cm cells, 93 -> 69 %:
// a bent wall, two faces 7° apart; 6 left room_scan2's leaning plane, 4.3 standard errors)
constexpr double kTurnStandardErrors = 4.0;
// ... and at least this far (1°, in radians): turns under it move a 5 m wall's ends by less
// than 4.4 cm, inside ε, and the fit's lean is then no loss.
constexpr double kMinTurn = std::numbers::pi / 180.0;

}  // namespace

std::optional<CandidatePlane> alongDirections(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                                              const PlaneScorer& scorer, const std::vector<std::uint32_t>& strict,
                                              const CandidatePlane& plane, double max_tilt_rad) {
  const Eigen::Vector3d normal = plane.normal.cast<double>();
  if (std::abs(normal.z()) > std::sin(max_tilt_rad)) return std::nullopt;
  // In azimuth only: a vertical block's direction is its wall line's normal in the level
  // plane (direction_vectors.cpp), blind to how far the wall leans, so it testifies to
  // the plane's heading and not to its lean. Compared in 3-D, a wall that truly leans was
  // turned plumb, its top left beyond ε: three of PCL's room_scan2's four walls lean 1.5-2.3°
  // by their points' own fit (bench/annotations); a generated wall leaning 2.3° was turned
  // 2.1-2.3°, its top 10 cm off the turned plane at 2.4 m.
  const Eigen::Vector2d heading = normal.head<2>().normalized();
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double weight = 0.0, weight_sq = 0.0, sine_sq = 0.0;
  for (const std::uint32_t id : strict) {
    Eigen::Vector2d d = directions[id].head<2>().cast<double>();
    // Level blocks' directions (a wall's top, a sill) point up: no heading.
    if (!(d.squaredNorm() > 0.5)) continue;
    d.normalize();
    if (d.dot(heading) < 0.0) d = -d;
    const double w = grid.blocks()[id].surface;
    sum += w * d;
    weight += w;
    weight_sq += w * w;
    sine_sq += w * std::max(0.0, 1.0 - d.dot(heading) * d.dot(heading));
  }
  if (!(weight > 0.0) || sum.norm() < 1e-9) return std::nullopt;
  const Eigen::Vector2d mean_heading = sum.normalized();
  const double turn = std::acos(std::clamp(mean_heading.dot(heading), -1.0, 1.0));
  // The standard error of the mean heading: the blocks' RMS angle from the plane's over the
  // root of their effective number (surface-weighted).
  const double standard_error = std::sqrt(sine_sq / weight) / std::sqrt(weight * weight / weight_sq);
  if (turn < std::max(kMinTurn, kTurnStandardErrors * standard_error)) return std::nullopt;
  // The blocks' heading at the plane's own lean.
  const double level_part = std::sqrt(std::max(0.0, 1.0 - normal.z() * normal.z()));
  const Eigen::Vector3d mean(level_part * mean_heading.x(), level_part * mean_heading.y(), normal.z());

  std::vector<std::pair<double, double>> offsets;  // (offset along the mean direction, surface)
  offsets.reserve(strict.size());
  for (const std::uint32_t id : strict)
    offsets.emplace_back(mean.dot(grid.blocks()[id].point.cast<double>()), grid.blocks()[id].surface);
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
  turned.normal = mean.cast<float>();
  turned.point = (point + (best_offset - mean.dot(point)) * mean).cast<float>();
  return turned;
}

}  // namespace mlmap
