#include "mlmap/registration/slide_profile.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

namespace mlmap::registration {
namespace {

// A surface faces d when its normal is within 30 deg of ±d: a slide s along d then moves a
// point across it by at least s·cos 30°, so the profile's peak is at most 2·bound / cos 30°
// wide on either side.
constexpr double kFacing = 0.8660254;
// At most this many facing points are counted per shift (spread evenly over the cloud): a
// true peak then counts hundreds (the lab's: 38 % of them, 0.2 % away from it), which stand
// out at 3 standard errors; more only cost time.
constexpr std::size_t kMaxProfilePoints = 1000;
// fitSlide: at most this many re-matching steps, and it stops at a step under this (m, as
// IcpConfig::convergence_translation). A bound on the cost, not a tuned figure: each step is
// one lookup per facing point (tens along a corridor, at most a few thousand in a room).
constexpr int kMaxFitSteps = 10;
constexpr double kFitConverged = 1e-4;

// a stands out from b: their difference is at least 3 standard errors of two counts.
bool standsOut(std::size_t a, std::size_t b) {
  if (a <= b) return false;
  const double difference = static_cast<double>(a - b);
  return difference >= 3.0 * std::sqrt(static_cast<double>(a + b));
}

}  // namespace

SlideProfile slideProfile(const std::vector<Point>& source, const std::vector<Eigen::Vector3d>& source_normals,
                          const VoxelHashMap& target, const Pose& pose,
                          const Eigen::Matrix3d& translation_information, double bound, double lowest,
                          double highest, double step) {
  SlideProfile profile;
  if (source.empty() || source_normals.size() != source.size() || !(step > 0.0) || !(bound > 0.0)) return profile;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(translation_information);
  profile.direction = solver.eigenvectors().col(0).normalized();  // the least information
  const Eigen::Vector3d& d = profile.direction;
  profile.half_width = 2.0 * bound / kFacing + step;

  std::vector<Point> facing;  // moved to the target frame at the pose
  for (std::size_t k = 0; k < source.size(); ++k) {
    if (std::abs((pose.linear() * source_normals[k]).dot(d)) >= kFacing) facing.push_back(pose * source[k]);
  }
  if (facing.size() > kMaxProfilePoints) {
    const double stride = static_cast<double>(facing.size()) / static_cast<double>(kMaxProfilePoints);
    std::vector<Point> sampled;
    for (std::size_t k = 0; k < kMaxProfilePoints; ++k) {
      sampled.push_back(facing[static_cast<std::size_t>(static_cast<double>(k) * stride)]);
    }
    facing.swap(sampled);
  }
  profile.facing = facing.size();
  if (facing.empty()) return profile;

  // A target surface is found within the bound or, where the target samples it sparsely, the
  // voxel; the point-to-plane residual then decides.
  const double gate = std::max(bound, target.voxelSize());
  const auto explainedAt = [&](double shift) {
    const Eigen::Vector3d offset = shift * d;
    std::size_t count = 0;
    for (const Point& point : facing) {
      const Point moved = point + offset;
      const std::optional<Neighbour> neighbour = target.nearest(moved, gate);
      if (!neighbour || std::abs(neighbour->normal.dot(d)) < kFacing) continue;
      if (std::abs(neighbour->normal.dot(moved - neighbour->point)) <= bound) ++count;
    }
    return count;
  };

  // Shifts on a grid through 0 (so the pose itself is one of them), from lowest to highest.
  // Each shift's count on its own thread: one shift is at most kMaxProfilePoints lookups,
  // less than a fork-join costs, but a profile is some 40 shifts (±0.5 m in steps of 2σ),
  // a third of a verified run's time on one thread (the stress benchmark's rooms: 10 of 55 ms).
  const auto first = static_cast<long>(std::ceil(std::min(0.0, lowest) / step));
  const auto last = static_cast<long>(std::floor(std::max(0.0, highest) / step));
  std::vector<std::size_t> counts(static_cast<std::size_t>(last - first + 1), 0);
#pragma omp parallel for schedule(dynamic, 1)
  for (long k = first; k <= last; ++k) counts[static_cast<std::size_t>(k - first)] = explainedAt(static_cast<double>(k) * step);
  profile.at_result = counts[static_cast<std::size_t>(-first)];
  profile.best = profile.at_result;
  for (long k = first; k <= last; ++k) {
    if (k == 0) continue;
    const double shift = static_cast<double>(k) * step;
    const std::size_t count = counts[static_cast<std::size_t>(k - first)];
    if (std::abs(shift) >= profile.half_width) profile.away = std::max(profile.away, count);
    if (count > profile.best) {
      profile.best = count;
      profile.best_shift = shift;
    }
  }
  profile.peaked = standsOut(profile.at_result, profile.away);
  profile.better_elsewhere = standsOut(profile.best, profile.at_result);
  return profile;
}

SlideFit fitSlide(const std::vector<Point>& source, const std::vector<Eigen::Vector3d>& source_normals,
                  const VoxelHashMap& target, const Pose& pose, const Eigen::Vector3d& direction, double bound,
                  std::size_t min_points) {
  SlideFit fit;
  if (source_normals.size() != source.size() || !(bound > 0.0) || direction.isZero()) return fit;
  const Eigen::Vector3d d = direction.normalized();
  std::vector<Point> facing;  // moved to the target frame at the pose
  for (std::size_t k = 0; k < source.size(); ++k) {
    if (std::abs((pose.linear() * source_normals[k]).dot(d)) >= kFacing) facing.push_back(pose * source[k]);
  }
  const double gate = std::max(bound, target.voxelSize());
  double shift = 0.0;
  // Gauss-Newton in one unknown, re-matching at each step.
  for (int step = 0; step < kMaxFitSteps; ++step) {
    double sum_ar = 0.0, sum_aa = 0.0, sum_rr = 0.0;
    std::size_t count = 0;
    for (const Point& point : facing) {
      const Point moved = point + shift * d;
      const std::optional<Neighbour> neighbour = target.nearest(moved, gate);
      if (!neighbour) continue;
      const double a = neighbour->normal.dot(d);
      if (std::abs(a) < kFacing) continue;
      const double r = neighbour->normal.dot(moved - neighbour->point);
      if (std::abs(r) > bound) continue;
      sum_ar += a * r;
      sum_aa += a * a;
      sum_rr += r * r;
      ++count;
    }
    fit.points = count;
    if (count < std::max<std::size_t>(2, min_points)) return SlideFit{.points = count};
    const double delta = -sum_ar / sum_aa;
    const double variance = std::max(0.0, sum_rr - sum_ar * sum_ar / sum_aa) / static_cast<double>(count - 1);
    fit.standard_error = std::sqrt(variance / sum_aa);
    shift += delta;
    if (std::abs(delta) < kFitConverged) break;
  }
  fit.shift = shift;
  fit.fitted = true;
  return fit;
}

CloudSurfaces cloudSurfaces(const std::vector<Point>& points, double voxel_size) {
  // Every point kept (a down-sampled cloud has about one a voxel): the noise of these points,
  // not of a sample of them, and each point's own voxel normal.
  VoxelHashMap cloud(voxel_size, std::numeric_limits<std::uint32_t>::max());
  cloud.addPoints(points);
  cloud.estimateNormals(NormalConfig{.radius = 2.0 * voxel_size, .max_radius = 8.0 * voxel_size});
  CloudSurfaces surfaces;
  surfaces.noise = cloud.surfaceNoise();
  surfaces.normals.resize(points.size(), Eigen::Vector3d::Zero());
  const auto count = static_cast<std::int64_t>(points.size());
#pragma omp parallel for schedule(static) if (count >= 4000)
  for (std::int64_t n = 0; n < count; ++n) {
    const auto k = static_cast<std::size_t>(n);
    if (!points[k].allFinite()) continue;
    const std::optional<Neighbour> self = cloud.nearest(points[k], 0.0);
    if (self) surfaces.normals[k] = self->normal;
  }
  return surfaces;
}

}  // namespace mlmap::registration
