// Beyond the paper: the first and second moments of the points a block collected.
// Section IV keeps only a height, its variance and a depth per block, so a plane
// fitted to blocks sits at cell centres: a wall turned a few degrees to the grid
// becomes a staircase of cell columns, a wall on a cell boundary two columns half a
// cell either side of it, and an RMS measures the cell spacing, not the fit. With the
// points' mean and scatter per block, positions, planes and residuals are the
// points' own (DESIGN.md, "Decided after the first round").
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace mlmap {

struct PointStats {
  std::uint32_t count = 0;
  // m: the mean of the points, x and y relative to the block's cell centre (small
  // numbers, exact in float at any distance from the origin), z absolute.
  float mean_x = 0.0F;
  float mean_y = 0.0F;
  float mean_z = 0.0F;
  // m²: Σ (p − mean)(p − mean)ᵀ, the scatter: xx, xy, xz, yy, yz, zz.
  float scatter[6] = {0.0F, 0.0F, 0.0F, 0.0F, 0.0F, 0.0F};

  bool empty() const { return count == 0; }
  Eigen::Vector3d mean() const { return {mean_x, mean_y, mean_z}; }
  Eigen::Matrix3d scatterMatrix() const;

  // Welford's update: stable in float for any number of points.
  void add(float x, float y, float z);
  // Chan et al.'s parallel combination: the moments of both point sets together.
  void merge(const PointStats& other);
  // The same points seen from a cell whose centre is `shift` (x, y) further along:
  // the mean's x and y move by −shift.
  PointStats shifted(double shift_x, double shift_y) const;
  // The points turned by `yaw` (radians) about the vertical through the cell centre and
  // lifted by dz (a map merged into another frame: blocks only turn about z).
  PointStats turned(double yaw, double dz) const;

  friend bool operator==(const PointStats&, const PointStats&) = default;
};

// The points' moments summed over several blocks, in double, about a common origin
// (a patch's points: its plane, offset and RMS).
struct PointMoments {
  double count = 0.0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();     // relative to the origin
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();   // Σ p pᵀ, relative to the origin

  // Adds a block's points; `centre` is the block's point-stats frame (its cell centre
  // at z 0) relative to the origin.
  void add(const PointStats& stats, const Eigen::Vector3d& centre);
  // Adds moments taken about the same origin (another patch's): their union's.
  void merge(const PointMoments& other) {
    count += other.count;
    sum += other.sum;
    outer += other.outer;
  }
  Eigen::Vector3d mean() const { return sum / count; }
  Eigen::Matrix3d covariance() const {
    const Eigen::Vector3d m = mean();
    return outer / count - m * m.transpose();
  }
};

}  // namespace mlmap
