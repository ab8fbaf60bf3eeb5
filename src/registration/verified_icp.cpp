#include "mlmap/registration/verified_icp.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

#include "basin_search.hpp"
#include "mlmap/error.hpp"

namespace mlmap::registration {
namespace {

constexpr double kMadToSigma = 1.4826;
// A surface is level (floor, ceiling, table) when its normal is within 45 deg of vertical.
constexpr double kLevelNormal = 0.7071;

// Whether `agrees` is explained within max_spread_ratio · σ and `apart` is not, both with
// min_matched points: one kind of surface fits, the other does not.
bool oneKindApart(const Verification& check, const SurfaceFit& agrees, const SurfaceFit& apart,
                  const BasinConfig& config) {
  const double bound = config.max_spread_ratio * check.sigma;
  return agrees.matched >= config.min_matched && apart.matched >= config.min_matched && agrees.spread <= bound &&
         apart.spread > bound;
}

}  // namespace

bool onlyLevelDisagrees(const Verification& check, const BasinConfig& config) {
  return oneKindApart(check, check.upright, check.level, config);
}

std::string disagreement(const Verification& check, const BasinConfig& config) {
  char text[200];
  if (onlyLevelDisagrees(check, config)) {
    std::snprintf(text, sizeof text,
                  "the walls agree (spread %.2f cm) but the floors and ceilings do not (%.2f cm): level surfaces "
                  "that bend between the scans (a tilting scanner's calibration), or floors that are not one plane",
                  100.0 * check.upright.spread, 100.0 * check.level.spread);
    return text;
  }
  if (oneKindApart(check, check.level, check.upright, config)) {
    std::snprintf(text, sizeof text,
                  "the floors and ceilings agree (spread %.2f cm) but the walls do not (%.2f cm): a turn or a "
                  "shift along the floor is off, or the walls moved between the scans",
                  100.0 * check.level.spread, 100.0 * check.upright.spread);
    return text;
  }
  return {};
}

double cloudNoise(const std::vector<Point>& points, double voxel_size, double min_noise) {
  return std::max(min_noise, cloudSurfaces(points, voxel_size).noise);
}

Verification verifyAlignment(const std::vector<Point>& source, const VoxelHashMap& target, const Pose& pose,
                             double sigma, double gate, const BasinConfig& config) {
  Verification check;
  check.source_points = source.size();
  check.sigma = sigma;
  std::vector<double> residuals(source.size(), -1.0);
  std::vector<Eigen::Vector3d> normals(source.size());
  const auto count = static_cast<std::int64_t>(source.size());
#pragma omp parallel for schedule(static) if (count >= 4000)
  for (std::int64_t k = 0; k < count; ++k) {
    const Point moved = pose * source[static_cast<std::size_t>(k)];
    const std::optional<Neighbour> neighbour = target.nearest(moved, gate);
    if (!neighbour || neighbour->normal.isZero()) continue;
    residuals[static_cast<std::size_t>(k)] = std::abs(neighbour->normal.dot(moved - neighbour->point));
    normals[static_cast<std::size_t>(k)] = neighbour->normal;
  }
  // The point-to-plane normal equations of the explained points (unit weights), for an
  // update about the sensor: rotations scaled to metres at the cloud's RMS range.
  const double radius = cloudRadius(source);
  const Eigen::Vector3d pivot = pose.translation();
  Matrix6d hessian = Matrix6d::Zero();
  std::vector<double> matched;
  matched.reserve(residuals.size());
  // Per kind of surface (floors and ceilings; walls): a floor matches at any yaw, so
  // the points of each kind must be explained on their own.
  std::array<std::vector<double>, 2> kinds;
  for (std::size_t k = 0; k < residuals.size(); ++k) {
    const double residual = residuals[k];
    if (residual < 0.0) continue;
    matched.push_back(residual);
    kinds[std::abs(normals[k].z()) >= kLevelNormal ? 0 : 1].push_back(residual);
    if (residual > config.explained_sigmas * sigma) continue;
    ++check.explained;
    Vector6d jacobian;
    jacobian << (pose * source[k] - pivot).cross(normals[k]) / radius, normals[k];
    hessian.selfadjointView<Eigen::Lower>().rankUpdate(jacobian);
  }
  const Matrix6d full = hessian.selfadjointView<Eigen::Lower>();
  if (check.explained > 0) {
    const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(full, Eigen::EigenvaluesOnly);
    const double largest = solver.eigenvalues()[5];
    check.eigenvalue_ratio = largest > 0.0 ? std::max(0.0, solver.eigenvalues()[0]) / largest : 0.0;
    // The turns' information with the translations left free (the Schur complement): what the
    // points hold of a turn that a shift cannot undo; the slide profile tests the shifts.
    const Eigen::Matrix3d rotation = full.topLeftCorner<3, 3>() - full.topRightCorner<3, 3>() *
        full.bottomRightCorner<3, 3>().completeOrthogonalDecomposition().solve(full.bottomLeftCorner<3, 3>());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> turns(rotation, Eigen::EigenvaluesOnly);
    check.rotation_ratio = largest > 0.0 ? std::max(0.0, turns.eigenvalues()[0]) / largest : 0.0;
    check.yaw_ratio = largest > 0.0 ? std::max(0.0, rotation(2, 2)) / largest : 0.0;
  }
  check.constrained = check.eigenvalue_ratio >= config.min_eigenvalue_ratio;
  check.translation_information = full.bottomRightCorner<3, 3>();
  check.matched = matched.size();
  check.explained_share =
      source.empty() ? 0.0 : static_cast<double>(check.explained) / static_cast<double>(source.size());
  if (!matched.empty()) {
    auto middle = matched.begin() + static_cast<long>(matched.size() / 2);
    std::nth_element(matched.begin(), middle, matched.end());
    check.spread = kMadToSigma * *middle;
  }
  // Judged among the matched points: how much of a scan has a partner within the gate
  // depends on how densely the target sampled the far field, not on the alignment.
  check.good = check.matched >= config.min_matched &&
               static_cast<double>(check.explained) >= config.min_explained_share * static_cast<double>(check.matched) &&
               check.spread <= config.max_spread_ratio * sigma;
  for (std::size_t k = 0; k < kinds.size(); ++k) {
    std::vector<double>& kind = kinds[k];
    if (kind.empty()) continue;
    const double bound = config.explained_sigmas * sigma;
    const auto explained = std::count_if(kind.begin(), kind.end(), [&](double r) { return r <= bound; });
    auto middle = kind.begin() + static_cast<long>(kind.size() / 2);
    std::nth_element(kind.begin(), middle, kind.end());
    const double spread = kMadToSigma * *middle;
    (k == 0 ? check.level : check.upright) = SurfaceFit{kind.size(), static_cast<std::size_t>(explained), spread};
    if (kind.size() < config.min_matched) continue;
    check.spread = std::max(check.spread, spread);
    check.good = check.good &&
                 static_cast<double>(explained) >= config.min_explained_share * static_cast<double>(kind.size()) &&
                 spread <= config.max_spread_ratio * sigma;
  }
  return check;
}

Verification verifyAlignment(const std::vector<Point>& source, const VoxelHashMap& target, const Pose& pose,
                             double sigma, const BasinConfig& config) {
  return verifyAlignment(source, target, pose, sigma, std::max(0.1, 10.0 * sigma), config);
}

VerifiedIcp alignVerified(const std::vector<Point>& source, const VoxelHashMap& target, const Pose& start,
                          const IcpConfig& icp, const BasinConfig& config) {
  if (source.empty() || target.empty()) return alignVerified(source, CloudSurfaces{}, target, start, icp, config);
  return alignVerified(source, cloudSurfaces(source, target.voxelSize()), target, start, icp, config);
}

VerifiedIcp alignVerified(const std::vector<Point>& source, const CloudSurfaces& surfaces, const VoxelHashMap& target,
                          const Pose& start, const IcpConfig& icp, const BasinConfig& config) {
  // Normals of another cloud would leave the slide profile and the rivals without their
  // surfaces, silently: a caller's error, said as one.
  if (!source.empty() && !target.empty() && surfaces.normals.size() != source.size())
    throw Error("alignVerified: " + std::to_string(surfaces.normals.size()) + " source normals given for " +
                std::to_string(source.size()) + " source points (cloudSurfaces of another cloud?)");
  if (!source.empty() && !target.empty()) return searchBasin(source, surfaces, target, start, icp, config);
  VerifiedIcp out;
  out.start = out.kept_start = start;
  out.icp.pose = start;
  out.icp.source_points = source.size();
  out.reason = source.empty() ? "no source points" : "empty target";
  return out;
}

}  // namespace mlmap::registration
