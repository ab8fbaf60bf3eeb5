// Internal to eRMSM: the smallest principal axis of a 3 × 3 covariance, which every
// level block's direction vector needs (hundreds of thousands on a fine map).
//
// Eigen's computeDirect solves the whole characteristic cubic with trigonometry (an
// atan2, a sincos); half the direction stage went there. Only the smallest root is
// needed, and for a surface's neighbourhood it lies far below the other two. The cubic
// p(λ) = det − m λ + t λ² − λ³ is convex and falling left of its smallest root, so
// Newton's method from λ = 0 walks to that root without overshoot, in a few steps.
// The axis is then the longest cross product of two rows of C − λI, and the middle
// eigenvalue the smaller root of the remaining quadratic. Where the two smallest roots
// lie close (no surface: a blob, a line), the axis is ill-conditioned that way, and the
// matrix goes to computeDirect.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>

namespace mlmap {

struct SmallestAxis {
  Eigen::Vector3d axis;       // unit, sign arbitrary
  double middle_eigenvalue;   // the second smallest
  double smallest_eigenvalue; // the variance along the axis
};

inline SmallestAxis smallestAxis(const Eigen::Matrix3d& covariance) {
  const Eigen::Matrix3d& c = covariance;
  const double trace = c.trace();
  const double minors = c(0, 0) * c(1, 1) - c(0, 1) * c(0, 1) + c(0, 0) * c(2, 2) - c(0, 2) * c(0, 2) +
                        c(1, 1) * c(2, 2) - c(1, 2) * c(1, 2);
  const double determinant = c.determinant();
  double lambda = 0.0;
  bool converged = false;
  for (int step = 0; step < 32 && trace > 0.0; ++step) {
    const double value = determinant - lambda * (minors - lambda * (trace - lambda));
    const double slope = -minors + lambda * (2.0 * trace - 3.0 * lambda);
    if (!(slope < 0.0)) break;
    const double change = value / slope;
    lambda -= change;
    // Newton's error squares each step (e' ≈ 4 e² / t here): after a step of 1e-7 t
    // the root is off by some 1e-14 t, and the axis by less than a float's rounding.
    if (std::abs(change) <= 1e-7 * trace) {
      converged = true;
      break;
    }
  }
  if (converged) {
    // The other two roots: sum s, product m − λ s.
    const double sum = trace - lambda;
    const double product = minors - lambda * sum;
    const double root = std::sqrt(std::max(0.0, sum * sum - 4.0 * product));
    const double middle = sum + root > 0.0 ? 2.0 * product / (sum + root) : 0.0;
    if (middle - lambda > 1e-4 * trace) {
      Eigen::Matrix3d shifted = c;
      shifted.diagonal().array() -= lambda;
      const Eigen::Vector3d candidates[3] = {shifted.row(0).cross(shifted.row(1)), shifted.row(0).cross(shifted.row(2)),
                                             shifted.row(1).cross(shifted.row(2))};
      int longest = 0;
      for (int k = 1; k < 3; ++k) {
        if (candidates[k].squaredNorm() > candidates[longest].squaredNorm()) longest = k;
      }
      const double length = candidates[longest].norm();
      if (length > 0.0) return {candidates[longest] / length, middle, std::max(0.0, lambda)};
    }
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  return {solver.eigenvectors().col(0), solver.eigenvalues()(1), std::max(0.0, solver.eigenvalues()(0))};
}

}  // namespace mlmap
