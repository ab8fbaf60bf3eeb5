// Simulated scan pairs for the verified-ICP tests: the first scan as the target map (in the
// world frame), the second down-sampled as the source, and starts turned and moved from the truth.
#pragma once

#include <Eigen/Geometry>
#include <numbers>
#include <string>
#include <vector>

#include "mlmap/registration/preprocessing.hpp"
#include "mlmap/registration/voxel_hash_map.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"

namespace mlmap::test {

using mlmap::Point;
using mlmap::Pose;
using mlmap::registration::NormalConfig;
using mlmap::registration::VoxelHashMap;
using mlmap::registration::voxelDownSample;

// An empty 7 × 7 × 3 m square room: nothing but its walls, floor and ceiling, so every
// wall looks like every other and a turned start finds a wall to slide onto. 2 cm noise.
inline const char* const kSymmetricRoomJson = R"({
  "scan_pattern": {"angular_step_deg": 1.0, "tilt_start_deg": -50, "tilt_end_deg": 50,
                   "tilt_step_deg": 2.0, "range_sigma": 0.02, "mount_height": 1.2},
  "poses": [{"x": 3.0, "y": 3.4, "yaw_deg": 20}, {"x": 4.1, "y": 3.9, "yaw_deg": 75}],
  "surfaces": [
    {"type": "rectangle", "class": "floor", "min": [0, 0, 0], "max": [7, 7, 0]},
    {"type": "rectangle", "class": "ceiling", "min": [0, 0, 3], "max": [7, 7, 3]},
    {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [0, 7, 3]},
    {"type": "rectangle", "class": "wall", "min": [7, 0, 0], "max": [7, 7, 3]},
    {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [7, 0, 3]},
    {"type": "rectangle", "class": "wall", "min": [0, 7, 0], "max": [7, 7, 3]}
  ]
})";

struct Pair {
  VoxelHashMap target{0.1, 20};
  std::vector<Point> source;  // sensor frame, down-sampled
  Pose true_pose;             // source -> target (the target is in the world frame)
};

// The scene's first two poses, simulated.
inline Pair simulatedPair(const mlmap::sim::Scene& scene, const NormalConfig& normals = {}) {
  const auto scans = mlmap::sim::simulate(scene);
  Pair pair;
  std::vector<Point> world;
  for (std::size_t i = 0; i < scans[0].scan.size(); ++i) world.push_back(scans[0].scan.worldPoint(i));
  pair.target.addPoints(voxelDownSample(world, 0.05));
  pair.target.estimateNormals(normals);
  pair.source = voxelDownSample(scans[1].scan.points, 0.1);
  pair.true_pose = scans[1].true_pose;
  return pair;
}

// `name`: where the scene's includes are looked up from.
inline Pair simulatedPair(const std::string& json, const std::string& name = "scene.json",
                          const NormalConfig& normals = {}) {
  return simulatedPair(mlmap::sim::parseScene(json, name), normals);
}

// The true pose turned by `yaw_deg` about the sensor and moved by `shift`.
inline Pose startOff(const Pose& truth, const Eigen::Vector3d& shift, double yaw_deg) {
  Pose start = truth;
  start.linear() =
      Eigen::AngleAxisd(yaw_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
      truth.linear();
  start.translation() += shift;
  return start;
}

inline double translationError(const Pose& a, const Pose& b) { return (a.translation() - b.translation()).norm(); }
inline double rotationErrorDeg(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / std::numbers::pi;
}

}  // namespace mlmap::test
