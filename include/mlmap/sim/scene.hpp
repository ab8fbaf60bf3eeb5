// A simulated indoor scene: planar surfaces with ground-truth plane ids, vertical
// cylinders (clutter, no plane), the tilting-laser scan pattern of section III, the
// robot poses the scans are taken from and the odometry drift. Loaded from the JSON
// described in maps/README.md; the ground truth is what plane detection (section V)
// is scored against.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mlmap/scan.hpp"

namespace mlmap::sim {

enum class SurfaceClass { Floor, Ceiling, Wall, Table, Step, Other };

std::string_view className(SurfaceClass surface_class);  // "floor", "ceiling", ...
std::optional<SurfaceClass> surfaceClassFromName(std::string_view name);

// One real plane of the scene: several surfaces (e.g. the floor's rectangles, the
// side faces of all stair steps) may share it.
struct GroundTruthPlane {
  std::int32_t id = 0;
  SurfaceClass surface_class = SurfaceClass::Other;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, towards the observed side
  double d = 0.0;                                      // m, n·x + d = 0
  std::string name;
};
using SceneGroundTruth = std::vector<GroundTruthPlane>;

// A planar parallelogram {corner + s·edge_u + t·edge_v, s, t in [0, 1]}; boxes and
// stairs are expanded into these when the scene is loaded. Seen from both sides.
struct Surface {
  Eigen::Vector3d corner = Eigen::Vector3d::Zero();  // m, world frame
  Eigen::Vector3d edge_u = Eigen::Vector3d::UnitX();  // m
  Eigen::Vector3d edge_v = Eigen::Vector3d::UnitY();  // m
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, same as its plane's
  std::int32_t plane_id = 0;
};

// Vertical cylinder (pillar, table leg, bin): not planar, its points are labelled -1.
struct Cylinder {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();  // m, x y
  double radius = 0.1;                                // m
  double z_min = 0.0;                                 // m
  double z_max = 1.0;                                 // m
};

// The tilting 2D laser (Hokuyo UTM-30LX on a PTU 46-17.5, section III).
struct ScanPattern {
  double field_of_view_deg = 270.0;  // deg, beam angles λ in [-fov/2, +fov/2]
  double angular_step_deg = 0.25;    // deg between beams
  double tilt_start_deg = -45.0;     // deg, γ_s (positive tilt = scan plane nose-down)
  double tilt_end_deg = 45.0;        // deg, γ_e >= γ_s
  double tilt_step_deg = 1.0;        // deg between scan lines, ρ
  double min_range = 0.023;          // m, closer hits give no point
  double max_range = 30.0;           // m, farther hits give no point
  std::optional<double> range_sigma; // m, Gaussian range noise; unset: UTM-30LX model
  double mount_height = 0.5;         // m, tilt axis above the floor (z = 0)
  std::uint64_t seed = 1;            // range-noise seed

  std::size_t beamCount() const;  // 1081 for 270° at 0.25°
  std::size_t lineCount() const;  // tilt lines, both ends included
  double beamAngle(std::size_t beam) const;  // rad, λ
  double tiltAngle(std::size_t line) const;  // rad, γ
  // m, standard deviation of the range noise at `range`: range_sigma when set, else the
  // UTM-30LX datasheet accuracy (0.03 m up to 10 m, 0.05 m beyond).
  double rangeSigma(double range) const;
};

// Where a scan is taken: the robot on the floor; the sensor sits mount_height above.
struct RobotPose {
  double x = 0.0;        // m
  double y = 0.0;        // m
  double yaw_deg = 0.0;  // deg, counter-clockwise from +x
};

// Wheel odometry error: each relative motion between consecutive poses gets Gaussian
// noise whose standard deviation grows with the motion.
struct OdometryDrift {
  double translation_noise_per_m = 0.0;  // m of std-dev per m travelled (x and y each)
  double yaw_noise_per_rad = 0.0;        // rad of std-dev per rad turned
  double yaw_noise_per_m = 0.0;          // rad of std-dev per m travelled
  std::uint64_t seed = 1;
};

struct Scene {
  std::string name;
  ScanPattern pattern;
  OdometryDrift odometry;
  std::vector<RobotPose> poses;
  std::vector<Surface> surfaces;
  std::vector<Cylinder> cylinders;
  SceneGroundTruth ground_truth;  // one entry per plane id, ascending ids

  // Sensor (tilt-axis) frame -> world frame for scan `index`: robot pose lifted to
  // mount_height.
  Pose sensorPose(std::size_t index) const;
  std::optional<GroundTruthPlane> plane(std::int32_t id) const;
};

// Throws mlmap::Error naming the file and the JSON element ("lab.json: surfaces[3].size:
// expected 3 numbers") on any bad or missing field. Includes are placed and openings cut
// (placement.hpp, openings.hpp); the scene is in the frame of the scene that
// provides the poses.
Scene loadScene(const std::filesystem::path& path);
// Same from text; `source_name` stands for the file in messages, and includes resolve
// against its directory.
Scene parseScene(std::string_view json_text, const std::string& source_name);

}  // namespace mlmap::sim
