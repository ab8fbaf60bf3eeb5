#include "label_fits.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "median.hpp"

namespace mlmap {

// The least-squares plane of the moments, its tolerance from the points' RMS distance.
void fitLabelledPlane(const PcaSums& moments, const Eigen::Vector3d& origin, const PointLabelRefinement& options,
                      PointPlane& plane) {
  if (moments.weight < 3.0) return;  // keep the detected plane
  const Eigen::Vector3d mean = moments.mean();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(moments.covariance());
  if (solver.info() != Eigen::Success) return;
  Eigen::Vector3d normal = solver.eigenvectors().col(0);
  if (!normal.allFinite()) return;
  if (normal.dot(plane.normal) < 0.0) normal = -normal;  // keep the detected orientation
  const double rms = std::sqrt(std::max(0.0, solver.eigenvalues()(0)));
  plane.normal = normal;
  plane.offset = -normal.dot(origin + mean);
  // A patch's own RMS grows with the points of neighbouring surfaces that its blocks
  // collected (a table's rim): the sensor's noise, when known, caps it.
  const double sigma = options.noise > 0.0 ? std::min(rms, options.noise) : rms;
  plane.tolerance = std::max(options.min_tolerance, options.sigmas * sigma);
  plane.points = static_cast<std::size_t>(moments.weight);
}

std::vector<double> ownNoise(std::span<const Point> points, std::span<const std::uint32_t> slot_of_point,
                             const std::vector<PointPlane>& planes, double band) {
  std::vector<std::vector<float>> distances(planes.size());
  forSampledPoints(slot_of_point, planes.size(), kPatchSample, [&](std::size_t index, std::uint32_t slot) {
    const PointPlane& plane = planes[slot];
    const double distance = plane.normal.dot(points[index]) + plane.offset;
    if (!std::isfinite(distance)) return;  // a non-finite point says nothing of the noise
    if (band == 0.0 || std::abs(distance) <= band) distances[slot].push_back(static_cast<float>(distance));
  });
  std::vector<double> sigma(planes.size(), 0.0);
  for (std::size_t slot = 1; slot < planes.size(); ++slot) {
    std::vector<float>& values = distances[slot];
    if (values.size() < 3) continue;
    const double centre = medianOf(values);
    for (float& value : values) value = static_cast<float>(std::abs(value - centre));
    sigma[slot] = 1.4826 * medianOf(values);
  }
  return sigma;
}

// Whether a fit of few inner points turns the plane significantly: by more than
// kInnerTurnSigmas standard errors of its tilt, which its points' residual spread over
// their extent across the plane's narrower in-plane axis gives: σ / sqrt(n · λ_mid). At
// least kMinInnerPoints hold it (fewer give no standard error to trust), and it turns the
// plane by less than kMaxInnerTurn: past 45° the fit lies nearer the perpendicular than the
// patch's own plane, another surface's points (the simulated corridor's treads at 3 cm of
// range noise: inner points on the risers turned two tread patches by 68 and 83°, which then
// took half of two risers).
constexpr double kInnerTurnSigmas = 3.0;
constexpr double kMinInnerPoints = 30.0;
constexpr double kMaxInnerTurn = std::numbers::pi / 4.0;

bool innerFitHolds(const PcaSums& inner, const Eigen::Vector3d& before, const Eigen::Vector3d& after) {
  if (inner.weight < kMinInnerPoints) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(inner.covariance(), Eigen::EigenvaluesOnly);
  if (solver.info() != Eigen::Success) return false;
  const double residual = std::max(0.0, solver.eigenvalues()(0));
  const double across = solver.eigenvalues()(1);
  if (!(across > 0.0)) return false;
  const double tilt_error = std::sqrt(residual / (inner.weight * across));
  const double turn = std::acos(std::clamp(std::abs(before.dot(after)), 0.0, 1.0));
  if (turn > kMaxInnerTurn) return false;
  return turn > kInnerTurnSigmas * tilt_error;
}

}  // namespace mlmap
