// ICP: aligns a (down-sampled) source cloud to a VoxelHashMap, point-to-plane (normals
// from the map's neighbourhoods) or point-to-point, with a Geman–McClure kernel, solved
// from the 6×6 normal equations (Eigen, no Ceres). The adaptive threshold: the
// correspondence gate shrinks to 3× the residuals' robust spread plus the last step's
// motion, and the kernel scale is a third of the gate.
// Stages: a coarse one on an evenly spread ~1500-point subset of the source with the
// gate held at its initial width until the pose stops moving (the wide searches are the
// costly ones, and a wide gate is what brings a pose back from decimetres and degrees off);
// where that leaves the adaptive gate wider than twice its floor, a ~3000-point subset
// follows it until it closes or the pose stops; then every point with the adaptive gate.
// The coarse stage's steps converge linearly; two that continue each other are
// extrapolated (the rest of their geometric series at once, within half the gate). Searches
// are skipped where their answer cannot have changed much: points that found nothing within
// the gate wait until the pose has moved a quarter of the gate, and once an iteration moves
// points by less than 2 mm the correspondences are kept and only re-linearised.
// The result says when it cannot be trusted: too few inliers, or degenerate geometry (a
// near-zero eigenvalue of the normal equations, e.g. along a featureless corridor).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <vector>

#include "mlmap/registration/voxel_hash_map.hpp"
#include "mlmap/scan.hpp"

namespace mlmap::registration {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

enum class IcpMetric { PointToPlane, PointToPoint };

struct IcpConfig {
  IcpMetric metric = IcpMetric::PointToPlane;
  double initial_max_distance = 1.0;  // m, correspondence gate at the first iteration
  double min_max_distance = 0.1;      // m, the gate never shrinks below this
  // m, the fine stage (every point) never searches wider than this: a wide first gate is
  // for the sparse coarse stage; every point searching a wide gate costs (gate / voxel)³
  // voxel visits each (a 1.9 m gate kept by a bad alignment's spread: 10 s per run).
  double max_fine_distance = std::numeric_limits<double>::infinity();
  double min_kernel_scale = 0.01;     // m, floor of the kernel scale (range noise)
  int max_iterations = 60;
  double convergence_translation = 1e-4;  // m, converged when an update moves less than this
  double convergence_rotation = 1e-5;     // rad, ... and turns less than this
  std::size_t min_inliers = 100;          // fewer: unreliable
  double min_eigenvalue_ratio = 5e-3;     // λ_min/λ_max of the scaled normal equations below: degenerate
};

struct IcpResult {
  Pose pose = Pose::Identity();  // source -> target frame
  std::size_t source_points = 0;
  std::size_t inliers = 0;       // correspondences within the final gate
  double rms_residual = 0.0;     // m, of the inliers' residuals (point-to-plane or -point)
  int iterations = 0;
  bool converged = false;
  bool degenerate = false;
  bool unreliable = true;        // too few inliers, degenerate or not converged
  double eigenvalue_ratio = 0.0; // λ_min/λ_max, rotations scaled to metres at the cloud's radius
  // The normal equations JᵀWJ at the result, for a pose update T ← Exp_pivot(ω, v)·T:
  // rotate by ω about `pivot`, then translate by v (target frame). Pose graphs use it as
  // the information of the result, divided by the residual variance.
  Matrix6d hessian = Matrix6d::Zero();
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
  double kernel_scale = 0.0;     // m, the final Geman–McClure scale
  double radius = 1.0;           // m, RMS range of the source: scales rotations to metres
};

// Aligns `source` (in its own frame) to `target`, starting from `initial_guess`
// (source -> target). With point-to-plane, map points without a normal are skipped.
IcpResult alignPoints(const std::vector<Point>& source, const VoxelHashMap& target,
                      const Pose& initial_guess, const IcpConfig& config = {});

// Exp_pivot(ω, v): rotation by the rotation vector ω about `pivot`, then translation v.
Pose applyIncrement(const Vector6d& increment, const Eigen::Vector3d& pivot, const Pose& pose);
// The inverse of Exp_pivot for a small transform `delta` (its (ω, v)).
Vector6d incrementOf(const Pose& delta, const Eigen::Vector3d& pivot);

}  // namespace mlmap::registration
