// A Scan: one 3D scan taken from one robot pose (section III). Points are in the
// sensor frame; `pose` maps them to the world frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <limits>
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
  // Read from a depth image (an organized PCD, HEIGHT > 1): a camera's points in its optical
  // frame, x right, y down the image, z forward (PCL's grabbers and ROS's depth images), so
  // the image's down is a cue to which way is up (registration/up_axis.hpp).
  bool from_image = false;

  std::size_t size() const { return points.size(); }
  double variance(std::size_t index) const {
    return variances.empty() ? kDefaultRangeVariance : variances[index];
  }
  Point worldPoint(std::size_t index) const { return pose * points[index]; }
};

// m: how far from the world's origin along an axis a scan's points reach (world frame): the
// OcTree's and the registration's keys (OctoMap's, 16 bits a side) reach 32,768 voxels either
// way, which a cloud in a national grid's coordinates lies beyond. (A sensor out of reach
// only clears no free space: OcTree rays start in reach.)
inline double farthestCoordinate(const std::vector<Point>& points, const Pose& pose) {
  double farthest = 0.0;
  for (const Point& point : points) {
    const Point p = pose * point;
    if (p.allFinite()) farthest = std::max(farthest, p.cwiseAbs().maxCoeff());
  }
  return farthest;
}
inline double farthestCoordinate(const Scan& scan) { return farthestCoordinate(scan.points, scan.pose); }

// m: the reach of a key grid of 16 bits a side (OctoMap's) at this voxel size.
inline double keyReach(double voxel_size) { return 32768.0 * voxel_size; }

// Where a map (or a registration) whose first scan is `scan` puts its frame's origin: the
// world's, where the scan lies within half of `reach` of it (every map near the origin
// keeps its coordinates to the bit), else the middle of the scan's points rounded to 100 m
// (a national grid's coordinates: the map then lies within 50 m of its origin plus its own
// size).
inline Eigen::Vector3d chooseOrigin(const std::vector<Point>& points, const Pose& pose, double reach) {
  if (farthestCoordinate(points, pose) < 0.5 * reach) return Eigen::Vector3d::Zero();
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const Point& point : points) {
    const Point p = pose * point;
    if (!p.allFinite()) continue;
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  const Eigen::Vector3d middle = low.allFinite() && high.allFinite() ? Eigen::Vector3d(0.5 * (low + high))
                                                                      : Eigen::Vector3d(pose.translation());
  return (middle / 100.0).array().round() * 100.0;
}
inline Eigen::Vector3d chooseOrigin(const Scan& scan, double reach) { return chooseOrigin(scan.points, scan.pose, reach); }

}  // namespace mlmap
