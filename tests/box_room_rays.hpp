// A box room scanned from the origin by rays spread evenly over the sphere (a Fibonacci
// lattice): each ray's hit on the box [low, high], so near surfaces get denser readings,
// as a scanner's do. Shared by the tests of the up axis and of the CLI's scan options.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace mlmap::test {

struct BoxRay {
  Eigen::Vector3d direction;  // unit
  double range = 0.0;         // m, to the box's wall
};

inline std::vector<BoxRay> boxRoomRays(int rays, const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
  std::vector<BoxRay> hits;
  hits.reserve(static_cast<std::size_t>(rays));
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < rays; ++k) {
    const double z = 1.0 - 2.0 * (k + 0.5) / rays;
    const double radius = std::sqrt(1.0 - z * z);
    const Eigen::Vector3d direction(radius * std::cos(golden * k), radius * std::sin(golden * k), z);
    double nearest = 1e9;
    for (int axis = 0; axis < 3; ++axis) {
      if (std::abs(direction[axis]) < 1e-12) continue;
      nearest = std::min(nearest, (direction[axis] > 0 ? high[axis] : low[axis]) / direction[axis]);
    }
    hits.push_back({direction, nearest});
  }
  return hits;
}

// A depth camera's view of the z-up box room seen from the origin: the rays within 30 deg
// across and 23 deg up or down of its forward axis (a Kinect's field of view), `turn` its
// orientation in the room (identity: looking along +x, level), the points in its optical
// frame (x right, y down the image, z forward).
inline std::vector<Eigen::Vector3d> cameraViewPoints(const Eigen::Matrix3d& turn, int rays, const Eigen::Vector3d& low,
                                                     const Eigen::Vector3d& high) {
  Eigen::Matrix3d optical_to_room;  // columns: the optical x, y, z in the room
  optical_to_room.col(0) = -Eigen::Vector3d::UnitY();
  optical_to_room.col(1) = -Eigen::Vector3d::UnitZ();
  optical_to_room.col(2) = Eigen::Vector3d::UnitX();
  optical_to_room = turn * optical_to_room;
  std::vector<Eigen::Vector3d> points;
  for (const BoxRay& ray : boxRoomRays(rays, low, high)) {
    const Eigen::Vector3d in_camera = optical_to_room.transpose() * ray.direction;
    if (in_camera.z() <= 0.0 || std::abs(in_camera.x()) > std::tan(0.52) * in_camera.z() ||
        std::abs(in_camera.y()) > std::tan(0.40) * in_camera.z())
      continue;
    points.push_back(ray.range * in_camera);
  }
  return points;
}

}  // namespace mlmap::test
