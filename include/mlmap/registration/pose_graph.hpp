// Global refinement of a pose sequence (in the spirit of SLAM6D's GraphSLAM, which the
// paper used): nodes are sensor poses, edges relative poses measured by ICP between
// overlapping scans (or odometry), each with its information matrix. Solved by
// Levenberg–Marquardt on the sparse normal equations (Eigen::SimplicialLDLT); the first
// pose is held fixed.
#pragma once

#include <cstddef>
#include <vector>

#include "mlmap/registration/icp.hpp"
#include "mlmap/scan.hpp"

namespace mlmap::registration {

struct PoseGraphEdge {
  std::size_t from = 0;
  std::size_t to = 0;
  Pose measurement = Pose::Identity();  // the pose of `to` in the frame of `from`
  // Information of the error Exp_pivot⁻¹(current · measurement⁻¹), an increment in the
  // frame of `from` about `pivot` — the parameterisation of IcpResult::hessian.
  Matrix6d information = Matrix6d::Identity();
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
};

struct PoseGraphConfig {
  int max_iterations = 30;
  double min_step = 1e-9;  // stop when the largest update component is smaller
};

struct PoseGraphResult {
  int iterations = 0;
  double initial_cost = 0.0;  // Σ eᵀΩe over the edges
  double final_cost = 0.0;
};

// Refines `poses` (sensor -> world) in place; poses[0] stays where it is.
PoseGraphResult optimizePoseGraph(std::vector<Pose>& poses, const std::vector<PoseGraphEdge>& edges,
                                  const PoseGraphConfig& config = {});

// The error vector of one edge at the given poses.
Vector6d edgeError(const PoseGraphEdge& edge, const Pose& from, const Pose& to);

}  // namespace mlmap::registration
