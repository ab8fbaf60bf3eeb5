// Self-calibration of the scanner's inclination (section VI): however carefully it is
// mounted, the scanner is not level, and the tilt shows as a "step effect" in horizontal
// and vertical planes. From a scan of the surrounding floor we find the floor plane; its
// normal, in the sensor frame, gives the roll and pitch that level the sensor.
//
// MountCorrection is applied to sensor-frame points before the scan pose:
//     p_corrected = R_y(pitch) · R_x(roll) · p
// It is stored as mount.json: {"schema": "mlmap.mount/1", "roll_correction_deg": …,
// "pitch_correction_deg": …, "floor_distance": …, "floor_points": …} (angles in degrees;
// the last two describe the calibration scan). The scanner driver's own mount config
// (the Denavit–Hartenberg chain) is a separate file.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "mlmap/scan.hpp"

namespace mlmap::registration {

struct MountCorrection {
  double roll_correction_deg = 0.0;   // deg, about the sensor's x axis (applied second)
  double pitch_correction_deg = 0.0;  // deg, about the sensor's y axis (applied last)

  Eigen::Matrix3d rotation() const;  // R_y(pitch) · R_x(roll)
};

struct FloorCalibrationConfig {
  double max_tilt_deg = 20.0;       // deg, the floor normal is searched within this of +z
  double min_depth = 0.3;           // m, candidate floor points lie at least this below the sensor
  double inlier_distance = 0.03;    // m, point-to-plane distance of floor points
  int ransac_iterations = 500;
  std::uint64_t seed = 1;
};

struct FloorCalibration {
  MountCorrection correction;
  Eigen::Vector3d floor_normal = Eigen::Vector3d::UnitZ();  // unit, sensor frame, pointing up
  double floor_distance = 0.0;     // m, from the sensor origin to the floor plane
  std::size_t floor_points = 0;    // inliers of the final fit
  double rms_distance = 0.0;       // m, of the inliers to the plane
};

// Finds the floor (RANSAC over the points below the sensor, then a least-squares refit of
// its inliers) in `points` (sensor frame) and the correction that makes it level.
// Throws mlmap::Error when no floor plane with enough points is found.
FloorCalibration calibrateFromFloor(const std::vector<Point>& points, const FloorCalibrationConfig& config = {});

// Rotates the scan's sensor-frame points by the correction.
void applyMountCorrection(Scan& scan, const MountCorrection& correction);

// mount.json; readers throw mlmap::Error naming the file and the key.
void writeMountCorrection(const std::filesystem::path& path, const FloorCalibration& calibration);
MountCorrection readMountCorrection(const std::filesystem::path& path);

}  // namespace mlmap::registration
