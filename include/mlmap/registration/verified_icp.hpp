// ICP with a wide basin and a check of its answer. One alignPoints run covers a start
// within the basin (its first gate is set from the start's error bound and the cloud's
// radius, not from a good start); its result is verified against the noise measured on the
// target (the share of source points it explains and the spread of their residuals), and
// when it does not explain the overlap, ICP runs again from other starts (yaw and
// translation offsets about the given one) and keeps the best-explained result. The answer
// says whether any result was good enough.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "mlmap/registration/icp.hpp"
#include "mlmap/registration/voxel_hash_map.hpp"
#include "mlmap/scan.hpp"

namespace mlmap::registration {

struct BasinConfig {
  // The start's error one ICP run must recover from: the first gate is
  // max_start_translation + radius · max_start_yaw (points at the cloud's RMS range move
  // that far), never less than IcpConfig::initial_max_distance.
  double max_start_translation = 0.5;  // m
  double max_start_yaw_deg = 10.0;     // deg
  // Retries, tried in this order until one verifies: turns about the sensor (deg) and
  // moves (m, along the target's x and y), each applied to the given start.
  std::vector<double> retry_yaw_deg = {20.0, -20.0, 10.0, -10.0, 30.0, -30.0};
  double retry_translation = 0.35;      // m; 0: no translation retries
  // Verification: a source point is explained when its point-to-plane residual is within
  // explained_sigmas · σ, σ the expected residual (√2 × the target's measured noise: both
  // clouds carry it); the result is verified when the share of explained source points is
  // at least min_explained_share and the robust spread of the residuals within the
  // verification gate is at most max_spread_ratio · σ.
  double noise = 0.0;                   // m, the target's noise; 0 = measured (VoxelHashMap::planeNoise)
  double min_noise = 0.002;             // m, floor of the measured noise (centroids of dense voxels)
  double explained_sigmas = 3.0;
  double min_explained_share = 0.3;
  double max_spread_ratio = 2.0;
  bool retry = true;                    // false: one run, verified but not retried
};

// How well a pose explains the source against the target.
struct Verification {
  std::size_t source_points = 0;
  std::size_t matched = 0;     // with a neighbour (with a normal) within the verification gate
  std::size_t explained = 0;   // ... and a residual within explained_sigmas · σ
  double explained_share = 0.0;  // explained / source_points
  double spread = 0.0;         // m, robust (MAD) spread of the matched points' residuals
  double sigma = 0.0;          // m, the expected residual
  bool good = false;
};

struct VerifiedIcp {
  IcpResult icp;               // the kept result (its pose: source -> target)
  Verification check;          // of the kept result
  Pose start = Pose::Identity();  // the start given
  Pose kept_start = Pose::Identity();  // the start the kept result ran from
  double noise = 0.0;          // m, the target noise used
  int attempts = 0;            // ICP runs (1: no retry)
  bool verified = false;
  std::string reason;          // why not verified; empty when verified
};

// The point-to-plane verification of `pose` (source -> target) with expected residual
// `sigma` (m); points match within `gate` (m; the overload without: max(0.1, 10 σ)).
Verification verifyAlignment(const std::vector<Point>& source, const VoxelHashMap& target, const Pose& pose,
                             double sigma, double gate, const BasinConfig& config = {});
Verification verifyAlignment(const std::vector<Point>& source, const VoxelHashMap& target, const Pose& pose,
                             double sigma, const BasinConfig& config = {});

// Aligns as above; `icp` sets the ICP itself (its initial_max_distance is a lower bound).
VerifiedIcp alignVerified(const std::vector<Point>& source, const VoxelHashMap& target, const Pose& start,
                          const IcpConfig& icp = {}, const BasinConfig& config = {});

}  // namespace mlmap::registration
