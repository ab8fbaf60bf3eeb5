// Move-and-stop 3D scan acquisition (section III): point the pan-tilt unit at pan α and
// tilt γ_s, stream laser scans (MD) while the tilt sweeps to γ_e at the speed of eq. 3,
// time every measurement (eq. 1–2, with the laser clock fitted to the host clock by TM
// before and after the sweep), take its tilt from the trapezoidal profile and its 3D
// point from the kinematic chain (eq. 4). Nothing is written unless the sweep completes.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "mlmap/driver/kinematics.hpp"
#include "mlmap/driver/ptu.hpp"
#include "mlmap/driver/scip.hpp"
#include "mlmap/scan.hpp"

namespace mlmap::driver {

struct SweepOptions {
  double pan_deg = 0.0;             // deg, α
  double tilt_start_deg = -30.0;    // deg, γ_s (positive = scan plane nose-down)
  double tilt_end_deg = 30.0;       // deg, γ_e
  double rho_deg = 1.0;             // deg of tilt per laser revolution (eq. 3)
  double base_speed_deg_s = 5.0;    // deg/s, PTU base speed v_b (instant start)
  double acceleration_deg_s2 = 200.0;  // deg/s², PTU acceleration above v_b
  std::uint32_t cluster = 1;        // laser steps merged into one measurement (1–99)
  int time_samples = 6;             // TM round trips before and after the sweep
  int timeout_ms = 1000;            // ms, longest silence accepted from either device
  bool intensity = false;           // stream ME (ranges + intensities) instead of MD
  MountConfig mount;
};

struct SweepResult {
  Scan scan;                     // base-frame points, variance from range, pose = odometry
  std::vector<std::uint32_t> intensities;  // per point of `scan` with SweepOptions::intensity
  std::size_t scan_lines = 0;    // laser scans inside the sweep
  std::size_t dropped_frames = 0;      // frames that failed their checks
  std::size_t missed_revolutions = 0;  // gaps in the laser's timestamps (frames never sent)
  ClockModel clock;              // laser clock vs host clock
  double tilt_start_device_s = 0.0;  // t_0 of eq. 2 on the laser clock
  double sync_uncertainty_s = 0.0;   // half the TP round trip + clock fit residual
  double sweep_duration_s = 0.0;     // of the trapezoidal profile
  ScipParameters laser;
};

// UTM-30LX accuracy: (0.03 m)² up to 10 m, (0.05 m)² beyond.
double rangeVariance(double range);

// Runs one sweep. `progress(lines)` is called after each scan line. Throws mlmap::Error
// (ScipError, PtuError) naming the device when the sweep cannot complete; the laser is
// asked to stop (QT) on the way out where it still answers.
SweepResult acquireScan(ScipClient& laser, PtuClient& ptu, const SweepOptions& options,
                        const Pose& odometry_pose,
                        const std::function<void(std::size_t lines)>& progress = {});

// DIR/scan_NNN.pcd (binary, VIEWPOINT = odometry pose), written atomically; returns it.
std::filesystem::path saveScan(const std::filesystem::path& dir, std::size_t index, const Scan& scan);
// The first NNN for which DIR/scan_NNN.pcd does not exist.
std::size_t nextScanIndex(const std::filesystem::path& dir);

// The options and pose as JSON (a raw log's metadata) and back; throws mlmap::Error
// naming `source_name` on bad JSON.
std::string sweepToJson(const SweepOptions& options, const Pose& odometry_pose);
void sweepFromJson(const std::string& json_text, const std::string& source_name,
                   SweepOptions& options, Pose& odometry_pose);

}  // namespace mlmap::driver
