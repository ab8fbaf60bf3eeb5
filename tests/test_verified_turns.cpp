// Verification must not call a turn right that the geometry leaves free. In a furnished room
// scanned by the stress benchmark's tilting laser (bench/icp_stress.py --split fresh: room seed
// 26, rounded to mm, 3 cm of range noise), the sensor turns 90 deg in place between scans 1
// and 2, and what the two scans share holds their relative roll and pitch only weakly: the
// explained points' rotation block (translations left free) has λ_min / λ_max 2.6e-3 to 3.9e-3
// at the results, where the room's other pairs have 1.8e-2 and more. The slide profile tests
// translations only, so from the benchmark's starts this pair was called verified 0.6-4.2 deg
// off (3 of these 4 starts; 4 of 4 verified). Now the rotation block must pass
// the same ratio as the whole system (BasinConfig::min_eigenvalue_ratio): such a pair is
// "unconstrained", not verified; a pair of the same room that holds every turn still verifies.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <string>

#include "mlmap/registration/preprocessing.hpp"
#include "mlmap/registration/sequence_registration.hpp"
#include "mlmap/registration/verified_icp.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"
#include "verified_pairs.hpp"

using namespace mlmap::registration;
using mlmap::test::rotationErrorDeg;
using mlmap::test::translationError;

namespace {

const char* const kRoomJson = R"({"name": "room-26", "poses": [
  {"x": 2.805, "y": 5.618, "yaw_deg": -166.51}, {"x": 1.479, "y": 5.725, "yaw_deg": -184.59},
  {"x": 1.479, "y": 5.725, "yaw_deg": -94.59}, {"x": 1.232, "y": 3.898, "yaw_deg": -97.717}],
 "surfaces": [
  {"type": "rectangle", "class": "floor", "min": [0, 0, 0], "max": [6.195, 7.571, 0]},
  {"type": "rectangle", "class": "ceiling", "min": [0, 0, 2.775], "max": [6.195, 7.571, 2.775]},
  {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [0, 7.571, 2.775], "facing": "+x"},
  {"type": "rectangle", "class": "wall", "min": [6.195, 0, 0], "max": [6.195, 7.571, 2.775], "facing": "-x"},
  {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [6.195, 0, 2.775], "facing": "+y"},
  {"type": "rectangle", "class": "wall", "min": [0, 7.571, 0], "max": [6.195, 7.571, 2.775], "facing": "-y"},
  {"type": "box", "class": "table", "center": [1.463, 5.021, 0.735], "size": [1.484, 0.797, 0.04], "yaw_deg": -15.517},
  {"type": "box", "class": "other", "center": [4.083, 2.273, 0.558], "size": [1.157, 0.587, 1.116], "yaw_deg": -18.449},
  {"type": "box", "class": "other", "center": [1.862, 1.701, 0.896], "size": [1.591, 0.383, 1.792], "yaw_deg": -81.627},
  {"type": "box", "class": "other", "center": [2.11, 3.964, 1.106], "size": [1.32, 0.41, 2.212], "yaw_deg": -1.708},
  {"type": "box", "class": "table", "center": [2.69, 3.844, 0.717], "size": [1.266, 0.633, 0.04], "yaw_deg": -86.749},
  {"type": "box", "class": "other", "center": [3.82, 1.804, 0.793], "size": [1.67, 0.375, 1.585], "yaw_deg": -81.341},
  {"type": "box", "class": "table", "center": [4.932, 6.931, 0.733], "size": [1.905, 0.763, 0.04], "yaw_deg": -27.098},
  {"type": "cylinder", "center": [3.591, 1.321], "radius": 0.289, "z": [0, 0.755]},
  {"type": "box", "class": "other", "size": [0.586, 0.274, 0.249], "center": [2.579, 5.797, 0.124], "yaw_deg": 43.66},
  {"type": "cylinder", "center": [1.592, 4.116], "radius": 0.174, "z": [0, 0.631]},
  {"type": "box", "class": "other", "size": [0.276, 0.429, 0.25], "center": [3.596, 4.166, 0.125], "yaw_deg": -88.048},
  {"type": "box", "class": "other", "size": [0.202, 0.368, 0.545], "center": [4.009, 3.755, 0.273], "yaw_deg": 34.168},
  {"type": "box", "class": "other", "size": [0.327, 0.502, 0.476], "center": [3.225, 4.525, 0.238], "yaw_deg": 21.026},
  {"type": "cylinder", "center": [5.527, 2.525], "radius": 0.099, "z": [0, 2.398]},
  {"type": "box", "class": "other", "size": [0.293, 0.363, 0.858], "center": [3.473, 0.408, 0.429], "yaw_deg": 85.174},
  {"type": "box", "class": "other", "size": [0.288, 0.203, 0.649], "center": [0.925, 2.779, 0.324], "yaw_deg": 18.272},
  {"type": "cylinder", "center": [2.61, 4.23], "radius": 0.249, "z": [0, 0.921]},
  {"type": "box", "class": "other", "size": [0.4, 0.268, 0.865], "center": [4.862, 5.877, 0.432], "yaw_deg": 81.388}],
 "scan_pattern": {"field_of_view_deg": 270, "angular_step_deg": 0.5, "tilt_start_deg": -46, "tilt_end_deg": 46,
  "tilt_step_deg": 1.0, "min_range": 0.023, "max_range": 30, "mount_height": 1.2, "range_sigma": 0.03, "seed": 3}})";

struct StartError {
  Eigen::Vector3d translation;  // m
  double roll_deg, pitch_deg, yaw_deg;
};

// The start: the true relative pose turned about the sensor by the error's rotation and moved
// by its translation (as bench/icp_stress.py makes them).
mlmap::Pose startFrom(const mlmap::Pose& truth, const StartError& error) {
  const double to_rad = std::numbers::pi / 180.0;
  const Eigen::Matrix3d turn = (Eigen::AngleAxisd(error.yaw_deg * to_rad, Eigen::Vector3d::UnitZ()) *
                                Eigen::AngleAxisd(error.pitch_deg * to_rad, Eigen::Vector3d::UnitY()) *
                                Eigen::AngleAxisd(error.roll_deg * to_rad, Eigen::Vector3d::UnitX()))
                                   .toRotationMatrix();
  mlmap::Pose start = truth;
  start.linear() = truth.linear() * turn;
  start.translation() += error.translation;
  return start;
}

// ICP of scan `source` against scan `target` as `mlmap register` prepares them.
VerifiedIcp alignPair(const std::vector<mlmap::sim::SimulatedScan>& scans, std::size_t target, std::size_t source,
                      const mlmap::Pose& start) {
  SequenceConfig config;
  config.min_range = 0.4;
  VoxelHashMap map(config.map_voxel_size, config.max_points_per_voxel);
  map.addPoints(voxelDownSample(scans[target].scan.points, config.map_voxel_size / 2.0, config.min_range,
                                config.max_range));
  map.estimateNormals(config.normals);
  const std::vector<mlmap::Point> points =
      voxelDownSample(scans[source].scan.points, config.source_voxel_size, config.min_range, config.max_range);
  return alignVerified(points, map, start, config.icp, config.basin);
}

}  // namespace

TEST_CASE("alignVerified: a pair whose shared surfaces leave roll and pitch weak is not verified") {
  const auto scans = mlmap::sim::simulate(mlmap::sim::parseScene(kRoomJson, "room-26.json"));
  REQUIRE(scans.size() == 4);
  const mlmap::Pose truth = scans[1].true_pose.inverse() * scans[2].true_pose;
  // The four starts of the benchmark's fresh split for this pair (0.5 m, up to 23 deg of yaw).
  const StartError starts[] = {{{-0.45, -0.172, -0.002}, -0.11, -0.79, -4.82},
                               {{-0.198, 0.016, -0.037}, 0.87, -0.41, 0.33},
                               {{-0.296, 0.044, -0.049}, 0.58, 0.46, 22.83},
                               {{-0.002, 0.005, -0.025}, 1.89, -1.33, 18.46}};
  for (const StartError& error : starts) {
    const VerifiedIcp result = alignPair(scans, 1, 2, startFrom(truth, error));
    const double rotation_error = rotationErrorDeg(result.icp.pose, truth);
    const double translation_error = translationError(result.icp.pose, truth);
    CAPTURE(error.yaw_deg);
    CAPTURE(rotation_error);
    CAPTURE(translation_error);
    CAPTURE(result.check.rotation_ratio);
    CAPTURE(result.reason);
    // Verified means right: within the benchmark's success bounds (2 cm, 0.5 deg).
    if (result.verified) {
      CHECK(rotation_error < 0.5);
      CHECK(translation_error < 0.02);
    }
  }
}

TEST_CASE("alignVerified: a pair of the same room that holds every turn still verifies") {
  const auto scans = mlmap::sim::simulate(mlmap::sim::parseScene(kRoomJson, "room-26.json"));
  REQUIRE(scans.size() == 4);
  const mlmap::Pose truth = scans[0].true_pose.inverse() * scans[1].true_pose;
  const VerifiedIcp result = alignPair(scans, 0, 1, startFrom(truth, {{-0.004, 0.037, 0.01}, 0.65, 0.78, -5.77}));
  CAPTURE(result.reason);
  CAPTURE(result.check.rotation_ratio);
  CHECK(result.verified);
  CHECK(rotationErrorDeg(result.icp.pose, truth) < 0.2);
  CHECK(translationError(result.icp.pose, truth) < 0.01);
}
