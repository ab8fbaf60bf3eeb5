// Internal to eRMSM: the weighted sums PCA needs over a set of blocks (Algorithm 2's
// refit, a patch's own plane, its spread). A horizontal block gives its point; a
// vertical block its top and its bottom, half its surface each: with one point per
// block a wall of full-height blocks is a line, and its normal is arbitrary.
#pragma once

#include <Eigen/Core>

namespace mlmap {

struct PcaSums {
  double weight = 0.0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();

  // `relative`: the block's point relative to a reference near the blocks (keeps the
  // sums well conditioned); `half_depth` 0 for a horizontal block.
  void addBlock(const Eigen::Vector3d& relative, double half_depth, double surface) {
    if (half_depth > 0.0) {
      for (const double dz : {half_depth, -half_depth}) add(relative + Eigen::Vector3d(0.0, 0.0, dz), 0.5 * surface);
    } else {
      add(relative, 1.0);
    }
  }
  void add(const Eigen::Vector3d& p, double w) {
    weight += w;
    sum += w * p;
    outer += w * p * p.transpose();
  }
  // Adds sums taken relative to another reference: `shift` = that reference minus this one.
  void addShifted(const PcaSums& other, const Eigen::Vector3d& shift) {
    weight += other.weight;
    sum += other.sum + other.weight * shift;
    outer += other.outer + other.sum * shift.transpose() + shift * other.sum.transpose() +
             other.weight * shift * shift.transpose();
  }
  Eigen::Vector3d mean() const { return sum / weight; }
  Eigen::Matrix3d covariance() const {
    const Eigen::Vector3d m = mean();
    return outer / weight - m * m.transpose();
  }
};

}  // namespace mlmap
