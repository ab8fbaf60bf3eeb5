// A Scan: one 3D scan taken from one robot pose (section III). Points are in the
// sensor frame; `pose` maps them to the world frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace mlmap {

using Point = Eigen::Vector3d;
using Pose = Eigen::Isometry3d;

constexpr double kDefaultRangeVariance = 0.03 * 0.03;  // m², UTM-30LX ±30 mm

struct Scan {
  std::vector<Point> points;        // m, sensor frame
  Pose pose = Pose::Identity();     // sensor frame -> world frame
  std::vector<double> variances;    // m², per point; empty means kDefaultRangeVariance
  std::vector<std::int32_t> labels; // optional per-point label (ground truth, plane id); empty if none

  std::size_t size() const { return points.size(); }
  double variance(std::size_t index) const {
    return variances.empty() ? kDefaultRangeVariance : variances[index];
  }
  Point worldPoint(std::size_t index) const { return pose * points[index]; }
};

}  // namespace mlmap
