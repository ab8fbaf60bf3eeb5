// Scan-to-map registration at 3 cm of range noise: a furnished room scanned by the stress
// benchmark's tilting laser (bench/icp_stress.py: room seed 1, rounded to mm), which sees
// little floor, so the scans' tilt rests mostly on walls. Started at the true poses, what is
// left is the registration's own error: the average over four noise seeds must stay within
// 0.4 cm and 0.12 deg RMS. With the scan sampled at 0.1 m (before session 35) it was 0.64 cm
// and 0.198 deg (seeds 1-4: 0.082 / 0.300 / 0.212 / 0.198 deg); at the map's own 0.05 m sample
// 0.31 cm and 0.090 deg (0.054 / 0.096 / 0.140 / 0.068 deg).
#include <doctest/doctest.h>

#include <string>

#include "mlmap/registration/sequence_registration.hpp"
#include "mlmap/registration/trajectory_error.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"

using namespace mlmap::registration;

namespace {

// The room without its scan pattern's seed, which each case appends.
const char* const kNoisyRoomJson = R"({"name": "room-1", "poses": [
  {"x": 6.701, "y": 1.224, "yaw_deg": -58.307}, {"x": 7.87, "y": 1.059, "yaw_deg": -8.083},
  {"x": 7.87, "y": 1.059, "yaw_deg": 81.917}, {"x": 6.751, "y": 2.115, "yaw_deg": 136.645}],
 "surfaces": [
  {"type": "rectangle", "class": "floor", "min": [0, 0, 0], "max": [9.288, 4.094, 0]},
  {"type": "rectangle", "class": "ceiling", "min": [0, 0, 2.769], "max": [9.288, 4.094, 2.769]},
  {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [0, 4.094, 2.769], "facing": "+x"},
  {"type": "rectangle", "class": "wall", "min": [9.288, 0, 0], "max": [9.288, 4.094, 2.769], "facing": "-x"},
  {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [9.288, 0, 2.769], "facing": "+y"},
  {"type": "rectangle", "class": "wall", "min": [0, 4.094, 0], "max": [9.288, 4.094, 2.769], "facing": "-y"},
  {"type": "box", "class": "other", "center": [1.397, 1.041, 1.034], "size": [0.876, 0.33, 2.067], "yaw_deg": -57.556},
  {"type": "box", "class": "other", "center": [4.568, 1.211, 0.864], "size": [1.784, 0.415, 1.728], "yaw_deg": -25.113},
  {"type": "box", "class": "table", "center": [2.752, 3.368, 0.716], "size": [1.896, 0.625, 0.04], "yaw_deg": 51.103},
  {"type": "box", "class": "other", "center": [1.174, 1.673, 0.697], "size": [1.834, 0.476, 1.395], "yaw_deg": 86.002},
  {"type": "box", "class": "table", "center": [0.967, 1.637, 0.731], "size": [1.267, 0.751, 0.04], "yaw_deg": -67.619},
  {"type": "box", "class": "other", "center": [2.253, 2.993, 1.073], "size": [1.071, 0.36, 2.146], "yaw_deg": -48.52},
  {"type": "box", "class": "table", "center": [3.783, 2.874, 0.764], "size": [1.323, 0.805, 0.04], "yaw_deg": 34.513},
  {"type": "cylinder", "center": [1.252, 1.831], "radius": 0.076, "z": [0, 0.773]},
  {"type": "cylinder", "center": [6.14, 1.722], "radius": 0.294, "z": [0, 2.164]},
  {"type": "box", "class": "other", "size": [0.245, 0.303, 0.575], "center": [3.455, 2.226, 0.288], "yaw_deg": 4.706},
  {"type": "cylinder", "center": [5.995, 3.099], "radius": 0.128, "z": [0, 1.726]},
  {"type": "cylinder", "center": [6.551, 1.027], "radius": 0.178, "z": [0, 0.701]},
  {"type": "box", "class": "other", "size": [0.465, 0.305, 0.666], "center": [3.189, 2.53, 0.333], "yaw_deg": -4.65},
  {"type": "box", "class": "other", "size": [0.586, 0.511, 0.55], "center": [3.985, 3.115, 0.275], "yaw_deg": -71.842},
  {"type": "cylinder", "center": [6.242, 3.018], "radius": 0.057, "z": [0, 1.029]}],
 "scan_pattern": {"field_of_view_deg": 270, "angular_step_deg": 0.5, "tilt_start_deg": -46, "tilt_end_deg": 46,
  "tilt_step_deg": 1.0, "min_range": 0.023, "max_range": 30, "mount_height": 1.2, "range_sigma": 0.03, "seed": )";

}  // namespace

TEST_CASE("SequenceRegistration: 3 cm of range noise leaves a room's poses within 0.4 cm and 0.12 deg") {
  double sum_translation = 0.0;
  double sum_rotation_deg = 0.0;
  const int seeds = 4;
  for (int seed = 1; seed <= seeds; ++seed) {
    const std::string json = std::string(kNoisyRoomJson) + std::to_string(seed) + "}}";
    const auto scans = mlmap::sim::simulate(mlmap::sim::parseScene(json, "room-1.json"));
    SequenceConfig config;
    config.min_range = 0.4;  // as `mlmap register`
    SequenceRegistration sequence(config);
    std::vector<mlmap::Pose> truth;
    for (const auto& scan : scans) {
      sequence.addScan(scan.scan.points, scan.true_pose);
      truth.push_back(scan.true_pose);
    }
    sequence.refine();
    const TrajectoryError error = trajectoryError(sequence.poses(), truth);
    CAPTURE(seed);
    CAPTURE(error.rms_translation);
    CAPTURE(error.rms_rotation_deg);
    CHECK(error.rms_rotation_deg < 0.35);  // each seed: no scan lost
    sum_translation += error.rms_translation;
    sum_rotation_deg += error.rms_rotation_deg;
  }
  CHECK(sum_translation / seeds < 0.004);
  CHECK(sum_rotation_deg / seeds < 0.12);
}
