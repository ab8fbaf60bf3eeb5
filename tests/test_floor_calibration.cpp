// Self-calibration: a simulated scanner mounted with a known tilt; the floor gives the
// tilt back within 0.1°, and mount.json round-trips.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "helpers.hpp"
#include "mlmap/registration/floor_calibration.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"

using namespace mlmap::registration;

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

const char* const kRoomJson = R"({
  "scan_pattern": {"angular_step_deg": 1.0, "tilt_start_deg": -60, "tilt_end_deg": 30,
                   "tilt_step_deg": 2.0, "range_sigma": 0.01, "mount_height": 1.2},
  "poses": [{"x": 3.0, "y": 2.0, "yaw_deg": 20}],
  "surfaces": [
    {"type": "rectangle", "class": "floor", "min": [0, 0, 0], "max": [7, 5, 0]},
    {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [0, 5, 3]},
    {"type": "rectangle", "class": "wall", "min": [7, 0, 0], "max": [7, 5, 3]},
    {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [7, 0, 3]},
    {"type": "rectangle", "class": "wall", "min": [0, 5, 0], "max": [7, 5, 3]},
    {"type": "box", "class": "table", "min": [4.0, 2.5, 0.7], "max": [5.5, 3.5, 0.75]}
  ]
})";

// The scanner as mounted: the nominal sensor frame turned by the mounting error.
Eigen::Matrix3d mountError(double roll_deg, double pitch_deg) {
  return (Eigen::AngleAxisd(pitch_deg * kDegree, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_deg * kDegree, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace

TEST_CASE("Floor calibration recovers a simulated mounting tilt within 0.1 degrees") {
  const mlmap::sim::Scene scene = mlmap::sim::parseScene(kRoomJson, "room.json");
  const double tilts[][2] = {{1.5, -2.0}, {-3.0, 0.7}, {0.0, 0.0}, {4.0, 5.0}};
  for (const auto& tilt : tilts) {
    CAPTURE(tilt[0]);
    CAPTURE(tilt[1]);
    mlmap::Pose mounted = scene.sensorPose(0);
    mounted.linear() = mounted.linear() * mountError(tilt[0], tilt[1]);
    const mlmap::Scan scan = mlmap::sim::simulateScan(scene, mounted, 0);
    const FloorCalibration calibration = calibrateFromFloor(scan.points);
    CHECK(std::abs(calibration.correction.roll_correction_deg - tilt[0]) < 0.1);
    CHECK(std::abs(calibration.correction.pitch_correction_deg - tilt[1]) < 0.1);
    // The corrected frame is level: the floor normal maps onto +z.
    const Eigen::Vector3d levelled = calibration.correction.rotation() * calibration.floor_normal;
    CHECK(std::acos(std::min(1.0, levelled.z())) / kDegree < 1e-6);
    CHECK(calibration.floor_distance == doctest::Approx(1.2).epsilon(0.01));
    CHECK(calibration.floor_points > 500);
    CHECK(calibration.rms_distance < 0.015);
    // Applying it levels the floor: its points, moved to the world, lie at z = 0.
    mlmap::Scan corrected = scan;
    applyMountCorrection(corrected, calibration.correction);
    corrected.pose = scene.sensorPose(0);
    double worst = 0.0;
    for (std::size_t i = 0; i < corrected.size(); ++i) {
      const auto plane = scene.plane(corrected.labels[i]);
      if (plane && plane->surface_class == mlmap::sim::SurfaceClass::Floor) {
        worst = std::max(worst, std::abs(corrected.worldPoint(i).z()));
      }
    }
    CHECK(worst < 0.06);  // 1 cm noise, 4.5 sigma; a 0.1 deg tilt alone would leave under 1 cm at 5 m
  }
}

TEST_CASE("Floor calibration: mount.json round-trips, bad files and scans throw") {
  mlmap::test::TempDir dir;
  FloorCalibration calibration;
  calibration.correction.roll_correction_deg = 1.25;
  calibration.correction.pitch_correction_deg = -0.5;
  calibration.floor_distance = 1.2;
  writeMountCorrection(dir / "mount.json", calibration);
  const MountCorrection read = readMountCorrection(dir / "mount.json");
  CHECK(read.roll_correction_deg == 1.25);
  CHECK(read.pitch_correction_deg == -0.5);
  mlmap::test::writeText(dir / "bad.json", R"({"schema": "mlmap.mount/1", "roll_correction_deg": 1})");
  CHECK(mlmap::test::errorOf([&] { readMountCorrection(dir / "bad.json"); }) ==
        (dir / "bad.json").string() + ": pitch_correction_deg: expected a number");
  CHECK_THROWS_AS(calibrateFromFloor({mlmap::Point(0, 0, 1)}), mlmap::Error);
}
