// Placements: quarter turns exact, positions rounded to the nanometre after a motion.
#include "mlmap/sim/placement.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

namespace mlmap::sim {
namespace {

// (cos, sin) of a yaw in degrees, exact for multiples of 90° so that quarter turns keep
// axis-aligned rectangles axis-aligned.
Eigen::Vector2d cosSin(double yaw_deg) {
  const double quarter_turns = yaw_deg / 90.0;
  if (quarter_turns == std::round(quarter_turns) && std::abs(quarter_turns) < 1e12) {
    switch (((static_cast<long long>(quarter_turns) % 4) + 4) % 4) {
      case 0: return {1.0, 0.0};
      case 1: return {0.0, 1.0};
      case 2: return {-1.0, 0.0};
      default: return {0.0, -1.0};
    }
  }
  const double yaw = yaw_deg * std::numbers::pi / 180.0;
  return {std::cos(yaw), std::sin(yaw)};
}

Eigen::Matrix3d rotation(double yaw_deg) {
  const Eigen::Vector2d cs = cosSin(yaw_deg);
  Eigen::Matrix3d result;
  result << cs.x(), -cs.y(), 0.0, cs.y(), cs.x(), 0.0, 0.0, 0.0, 1.0;
  return result;
}

// To the nanometre (and -0.0 to 0.0): 22 + 8.3 - 22 reads 8.3 again.
double snap(double metres) {
  if (std::abs(metres) > 1e6) return metres;
  return std::round(metres * 1e9) / 1e9 + 0.0;
}

Eigen::Vector3d snap(const Eigen::Vector3d& point) { return {snap(point.x()), snap(point.y()), snap(point.z())}; }

Eigen::Vector3d clean(const Eigen::Vector3d& direction) { return (direction.array() + 0.0).matrix(); }

}  // namespace

Placement compose(const Placement& outer, const Placement& inner) {
  const Eigen::Vector2d cs = cosSin(outer.yaw_deg);
  return {outer.x + cs.x() * inner.x - cs.y() * inner.y, outer.y + cs.y() * inner.x + cs.x() * inner.y,
          outer.yaw_deg + inner.yaw_deg};
}

Placement inverse(const Placement& placement) {
  const Eigen::Vector2d cs = cosSin(placement.yaw_deg);
  return {-(cs.x() * placement.x + cs.y() * placement.y), -(-cs.y() * placement.x + cs.x() * placement.y),
          -placement.yaw_deg};
}

bool isIdentity(const Placement& placement) {
  return placement.x == 0.0 && placement.y == 0.0 && std::fmod(placement.yaw_deg, 360.0) == 0.0;
}

Pose toPose(const Placement& placement) {
  Pose pose = Pose::Identity();
  pose.linear() = rotation(placement.yaw_deg);
  pose.translation() = Eigen::Vector3d(placement.x, placement.y, 0.0);
  return pose;
}

Surface transformSurface(const Surface& surface, const Placement& placement) {
  if (isIdentity(placement)) return surface;
  const Eigen::Matrix3d turn = rotation(placement.yaw_deg);
  Surface result = surface;
  result.corner = snap(turn * surface.corner + Eigen::Vector3d(placement.x, placement.y, 0.0));
  result.edge_u = snap(turn * surface.edge_u);
  result.edge_v = snap(turn * surface.edge_v);
  result.normal = clean(turn * surface.normal);
  return result;
}

void transformScene(Scene& scene, const Placement& placement) {
  if (isIdentity(placement)) return;
  const Eigen::Matrix3d turn = rotation(placement.yaw_deg);
  const Eigen::Vector3d shift(placement.x, placement.y, 0.0);
  for (Surface& surface : scene.surfaces) surface = transformSurface(surface, placement);
  for (Cylinder& cylinder : scene.cylinders) {
    const Eigen::Vector3d center = turn * Eigen::Vector3d(cylinder.center.x(), cylinder.center.y(), 0.0) + shift;
    cylinder.center = {snap(center.x()), snap(center.y())};
  }
  for (GroundTruthPlane& plane : scene.ground_truth) {
    plane.normal = clean(turn * plane.normal);
    plane.d = snap(plane.d - plane.normal.dot(shift));  // n'·(R p + t) + d' = 0
  }
  for (RobotPose& pose : scene.poses) {
    const Eigen::Vector3d position = turn * Eigen::Vector3d(pose.x, pose.y, 0.0) + shift;
    pose.x = snap(position.x());
    pose.y = snap(position.y());
    pose.yaw_deg += placement.yaw_deg;
  }
}

}  // namespace mlmap::sim
