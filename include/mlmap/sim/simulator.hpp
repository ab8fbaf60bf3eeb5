// The tilting laser of section III, simulated: a 2D laser (beam angle λ in its scan
// plane, λ = 0 straight ahead) on a tilt unit sweeping γ from tilt_start to tilt_end.
//
// Frames. The sensor frame is the pan-tilt base: x forward, y left, z up, origin on the
// tilt axis (the beam origin is taken to lie on it). A beam points along
//     R_y(γ) · (cos λ, sin λ, 0) = (cos γ cos λ, sin λ, −sin γ cos λ),
// so γ = 0 is a horizontal scan plane and positive γ pitches it nose-down (a right-handed
// rotation about +y). Scan points are in the sensor frame; Scan::pose (sensor -> world)
// is the TRUE pose, at mount_height above the floor.
//
// Noise. The measured range is the true one plus Gaussian noise of ScanPattern::
// rangeSigma(range) (the JSON's range_sigma, else the UTM-30LX model 0.03 m up to 10 m,
// 0.05 m beyond); each point's variance is that sigma squared. Rays that hit nothing, or
// hit closer than min_range or farther than max_range, give no point. Every scan line
// has its own generator seeded from (seed, pose index, line index): results are the same
// at any thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "mlmap/scan.hpp"
#include "mlmap/sim/scene.hpp"

namespace mlmap::sim {

struct SimulatedScan {
  Scan scan;             // sensor-frame points, labels = ground-truth plane id or -1
  Pose true_pose;        // sensor -> world, == scan.pose
  Pose odometry_pose;    // what wheel odometry would report (first one == true pose)
};

struct SimulateOptions {
  bool range_noise = true;     // false: exact ranges (variances still from the pattern)
  bool odometry_drift = true;  // false: odometry poses equal the true poses
  int threads = 0;             // OpenMP threads; 0 = OpenMP's default
  // Called from the calling thread after each scan (done of total scans).
  std::function<void(std::size_t done, std::size_t total)> progress;
};

// One scan per scene pose, in order.
std::vector<SimulatedScan> simulate(const Scene& scene, const SimulateOptions& options = {});

// One scan from sensor pose `pose` (sensor -> world); `pose_index` only seeds the noise.
Scan simulateScan(const Scene& scene, const Pose& pose, std::size_t pose_index,
                  const SimulateOptions& options = {});

// The odometry poses (sensor -> world) for the scene's poses: the relative motions
// between consecutive true poses integrated with the scene's OdometryDrift noise.
std::vector<Pose> odometryPoses(const Scene& scene);

// Writes into `dir` (created if missing): scan_000.xyz ... (sensor frame, "x y z label"),
// poses_true.txt and poses_odom.txt (TUM, stamp = scan index), planes_true.json (the
// ground-truth planes) and all_world.xyz (every point in the world frame with its label,
// in scan order). Every file is written atomically.
void writeSimulation(const std::filesystem::path& dir, const Scene& scene,
                     const std::vector<SimulatedScan>& scans);

}  // namespace mlmap::sim
