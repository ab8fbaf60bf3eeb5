#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>
#include <unordered_map>

#include "mlmap/planes/point_labels.hpp"
#include "pca_sums.hpp"

namespace mlmap {
namespace {

// A refit that turns further than this from the detected plane fits something else (a
// patch whose labelled points are one scan line, or an edge strip): κ, the detector's
// own bound between a block's direction and its plane.
constexpr double kMaxTurnDeg = 25.0;

}  // namespace

std::vector<Plane> refitToPoints(std::span<const Plane> planes, std::span<const Point> points,
                                 std::span<const std::int32_t> labels) {
  std::vector<Plane> refitted(planes.begin(), planes.end());
  std::unordered_map<std::int32_t, std::size_t> slot;
  for (std::size_t k = 0; k < refitted.size(); ++k) slot.emplace(refitted[k].id, k);
  std::vector<PcaSums> sums(refitted.size());  // each about its plane's detected centroid
  const std::size_t count = std::min(points.size(), labels.size());
  for (std::size_t k = 0; k < count; ++k) {
    if (labels[k] <= 0 || !points[k].allFinite()) continue;
    const auto found = slot.find(labels[k]);
    if (found == slot.end()) continue;
    sums[found->second].add(points[k] - refitted[found->second].centroid, 1.0);
  }
  const double min_cosine = std::cos(kMaxTurnDeg * std::numbers::pi / 180.0);
  for (std::size_t k = 0; k < refitted.size(); ++k) {
    if (sums[k].weight < 3.0) continue;
    const Eigen::Vector3d mean = sums[k].mean();
    const Eigen::Matrix3d covariance = sums[k].covariance();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(covariance);
    Eigen::Vector3d normal = solver.eigenvectors().col(0);
    Plane& plane = refitted[k];
    // Points along one line leave the plane free about it.
    if (!(solver.eigenvalues()(1) > 1e-6) || std::abs(normal.dot(plane.normal)) < min_cosine) continue;
    if (normal.dot(plane.normal) < 0.0) normal = -normal;
    const Eigen::Vector3d centroid = plane.centroid + mean;
    plane.normal = normal;
    plane.offset = -normal.dot(centroid);
    plane.centroid = centroid;
    plane.rms = std::sqrt(std::max(0.0, normal.dot(covariance * normal)));
  }
  return refitted;
}

}  // namespace mlmap
