// A Scan: one 3D scan taken from one robot pose (section III). Points are in the
// sensor frame; `pose` maps them to the world frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
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

// m: how far from the world's origin along an axis a scan reaches, its points (world frame)
// and its sensor: the OcTree's and the registration's keys (OctoMap's, 16 bits a side) reach
// 32,768 voxels either way, which a cloud in a national grid's coordinates lies beyond.
inline double farthestCoordinate(const std::vector<Point>& points, const Pose& pose) {
  double farthest = pose.translation().cwiseAbs().maxCoeff();
  for (const Point& point : points) {
    const Point p = pose * point;
    if (p.allFinite()) farthest = std::max(farthest, p.cwiseAbs().maxCoeff());
  }
  return farthest;
}
inline double farthestCoordinate(const Scan& scan) { return farthestCoordinate(scan.points, scan.pose); }

// m: the reach of a key grid of 16 bits a side (OctoMap's) at this voxel size.
inline double keyReach(double voxel_size) { return 32768.0 * voxel_size; }

}  // namespace mlmap
