#include "mlmap/registration/verified_icp.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <optional>

namespace mlmap::registration {
namespace {

constexpr double kMadToSigma = 1.4826;
// The noise is measured on every this-many-th voxel of the target: a few thousand voxels
// give the median to a few per cent.
constexpr std::size_t kNoiseStride = 4;
// m, the most the start's yaw error adds to the first gate: a source far from its own
// origin (a map 60 m away) would otherwise make every search visit thousands of voxels.
constexpr double kMaxYawReach = 1.5;

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// `start` turned by `yaw` about the source's origin (the sensor) and moved by `shift`
// (target frame): the sensor stays where it was, only its heading changes.
Pose offsetStart(const Pose& start, double yaw, const Eigen::Vector3d& shift) {
  Pose pose = start;
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * start.linear();
  pose.translation() += shift;
  return pose;
}

// Better explained: verified first, then the larger explained share; shares within
// kShareTie of each other explain the overlap equally well (along a corridor every slide
// does), and then the result nearer the given start wins: the start is a measurement too.
constexpr double kShareTie = 0.02;
double distanceFrom(const Pose& start, const Pose& pose, double radius) {
  const Pose delta = start.inverse() * pose;
  return delta.translation().norm() + radius * Eigen::AngleAxisd(delta.linear()).angle();
}
bool better(const Verification& a, double a_distance, const Verification& b, double b_distance) {
  if (a.good != b.good) return a.good;
  if (std::abs(a.explained_share - b.explained_share) > kShareTie) return a.explained_share > b.explained_share;
  return a_distance < b_distance;
}

double cloudRadius(const std::vector<Point>& source) {
  double radius_sq = 0.0;
  for (const Point& point : source) radius_sq += point.squaredNorm();
  return source.empty() ? 1.0 : std::max(1.0, std::sqrt(radius_sq / static_cast<double>(source.size())));
}

}  // namespace

Verification verifyAlignment(const std::vector<Point>& source, const VoxelHashMap& target, const Pose& pose,
                             double sigma, double gate, const BasinConfig& config) {
  Verification check;
  check.source_points = source.size();
  check.sigma = sigma;
  std::vector<double> residuals(source.size(), -1.0);
  const auto count = static_cast<std::int64_t>(source.size());
#pragma omp parallel for schedule(static) if (count >= 4000)
  for (std::int64_t k = 0; k < count; ++k) {
    const Point moved = pose * source[static_cast<std::size_t>(k)];
    const std::optional<Neighbour> neighbour = target.nearest(moved, gate);
    if (!neighbour || neighbour->normal.isZero()) continue;
    residuals[static_cast<std::size_t>(k)] = std::abs(neighbour->normal.dot(moved - neighbour->point));
  }
  std::vector<double> matched;
  matched.reserve(residuals.size());
  for (const double residual : residuals) {
    if (residual < 0.0) continue;
    matched.push_back(residual);
    if (residual <= config.explained_sigmas * sigma) ++check.explained;
  }
  check.matched = matched.size();
  check.explained_share =
      source.empty() ? 0.0 : static_cast<double>(check.explained) / static_cast<double>(source.size());
  if (!matched.empty()) {
    auto middle = matched.begin() + static_cast<long>(matched.size() / 2);
    std::nth_element(matched.begin(), middle, matched.end());
    check.spread = kMadToSigma * *middle;
  }
  check.good = check.matched > 0 && check.explained_share >= config.min_explained_share &&
               check.spread <= config.max_spread_ratio * sigma;
  return check;
}

Verification verifyAlignment(const std::vector<Point>& source, const VoxelHashMap& target, const Pose& pose,
                             double sigma, const BasinConfig& config) {
  return verifyAlignment(source, target, pose, sigma, std::max(0.1, 10.0 * sigma), config);
}

VerifiedIcp alignVerified(const std::vector<Point>& source, const VoxelHashMap& target, const Pose& start,
                          const IcpConfig& icp, const BasinConfig& config) {
  VerifiedIcp out;
  out.start = out.kept_start = start;
  out.icp.pose = start;
  out.icp.source_points = source.size();
  if (source.empty() || target.empty()) {
    out.reason = source.empty() ? "no source points" : "empty target";
    return out;
  }
  // The expected residual: both clouds carry the measured noise.
  out.noise = config.noise > 0.0 ? config.noise : std::max(config.min_noise, target.planeNoise(kNoiseStride));
  const double sigma = std::sqrt(2.0) * out.noise;
  // The verification gate reaches past a misalignment's residuals (so their spread shows)
  // but not past the ICP's own final gate.
  const double gate = std::max(icp.min_max_distance, 10.0 * sigma);

  IcpConfig wide = icp;
  wide.initial_max_distance = std::max(
      icp.initial_max_distance,
      config.max_start_translation + std::min(kMaxYawReach, cloudRadius(source) * radians(config.max_start_yaw_deg)));

  std::vector<Pose> starts{start};
  if (config.retry) {
    for (const double yaw : config.retry_yaw_deg) starts.push_back(offsetStart(start, radians(yaw), Eigen::Vector3d::Zero()));
    if (config.retry_translation > 0.0) {
      const double t = config.retry_translation;
      for (const Eigen::Vector3d& shift : {Eigen::Vector3d(t, 0, 0), Eigen::Vector3d(-t, 0, 0), Eigen::Vector3d(0, t, 0),
                                          Eigen::Vector3d(0, -t, 0)}) {
        starts.push_back(offsetStart(start, 0.0, shift));
      }
    }
  }
  bool have = false;
  double kept_distance = 0.0;
  const double radius = cloudRadius(source);
  for (const Pose& from : starts) {
    const IcpResult result = alignPoints(source, target, from, wide);
    ++out.attempts;
    const Verification check = verifyAlignment(source, target, result.pose, sigma, gate, config);
    const double distance = distanceFrom(start, result.pose, radius);
    if (!have || better(check, distance, out.check, kept_distance)) {
      kept_distance = distance;
      out.icp = result;
      out.check = check;
      out.kept_start = from;
      have = true;
    }
    if (check.good) break;
  }
  out.verified = out.check.good;
  if (!out.verified) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "no start of %d gave a result that explains the overlap: best %.0f %% of the points within "
                  "%.1f cm, residual spread %.2f cm (expected %.2f cm)",
                  out.attempts, 100.0 * out.check.explained_share, 100.0 * config.explained_sigmas * sigma,
                  100.0 * out.check.spread, 100.0 * sigma);
    out.reason = text;
  }
  return out;
}

}  // namespace mlmap::registration
