#include "wall_line.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "mlmap/planes/direction_vectors.hpp"

namespace mlmap {

double tiltOf(double residual_variance, double spread_variance, double n, double unknowns) {
  if (!(n > unknowns) || !(spread_variance > 0.0)) return std::numeric_limits<double>::infinity();
  return std::atan(std::sqrt(residual_variance * n / (n - unknowns) / (n * spread_variance)));
}

double smallerEigenvalue(const Eigen::Matrix2d& covariance) {
  const double difference = covariance(0, 0) - covariance(1, 1);
  return 0.5 * (covariance.trace() - std::sqrt(difference * difference + 4.0 * covariance(0, 1) * covariance(0, 1)));
}

Direction lineDirection(const Eigen::Matrix2d& covariance, double n, double min_spread) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver;
  solver.computeDirect(covariance);
  if (solver.eigenvalues()(1) < min_spread) return {};
  const Eigen::Vector2d normal = solver.eigenvectors().col(0);
  return {orientConsistently(Eigen::Vector3f(static_cast<float>(normal.x()), static_cast<float>(normal.y()), 0.0F)),
          tiltOf(std::max(0.0, solver.eigenvalues()(0)), solver.eigenvalues()(1), n, 2.0)};
}

Direction cornerDirection(const std::vector<Eigen::Vector2f>& positions, const Eigen::Vector2f& self, float reach,
                          double max_residual, double cell, double min_spread) {
  std::size_t best_inliers = 0;
  Eigen::Vector2f best_normal = Eigen::Vector2f::Zero();
  for (const Eigen::Vector2f& through : positions) {
    const Eigen::Vector2f along = through - self;
    if (along.squaredNorm() < 0.25F) continue;  // half a cell: too close to fix a direction
    const Eigen::Vector2f normal = Eigen::Vector2f(-along.y(), along.x()).normalized();
    std::size_t inliers = 0;
    for (const Eigen::Vector2f& p : positions) inliers += std::abs(normal.dot(p - self)) <= reach ? 1 : 0;
    if (inliers > best_inliers) {
      best_inliers = inliers;
      best_normal = normal;
    }
  }
  if (best_inliers < 2) return {};
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  Eigen::Matrix2d outer = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2f& p : positions) {
    if (std::abs(best_normal.dot(p - self)) > reach) continue;
    const Eigen::Vector2d q = p.cast<double>() * cell;
    sum += q;
    outer += q * q.transpose();
  }
  const auto n = static_cast<double>(best_inliers);
  const Eigen::Vector2d mean = sum / n;
  const Eigen::Matrix2d covariance = outer / n - mean * mean.transpose();
  // A straight face's blocks lie on their line by their points' noise (and, where a
  // riser's cells also hold its treads' points, by a part of a cell); blocks round a
  // pillar or a bin fill the band about a chord. Those keep the window's direction,
  // whose fanning out tells the curve (the spread rule).
  if (smallerEigenvalue(covariance) > max_residual * max_residual) return {};
  return lineDirection(covariance, n, min_spread);
}

}  // namespace mlmap
