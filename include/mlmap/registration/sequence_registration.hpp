// Multi-pose mapping: registers a sequence of scans one by one against a growing map
// (scan-to-map ICP from the odometry guess), then refines all poses together with a pose
// graph over the overlapping scan pairs — mlmap's stand-in for the SLAM6D step of the
// paper's section III-A. Keeps only down-sampled copies of the scans, so a caller can
// stream scans from files and read them again to build the map.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "mlmap/registration/icp.hpp"
#include "mlmap/registration/pose_graph.hpp"
#include "mlmap/registration/verified_icp.hpp"
#include "mlmap/registration/voxel_hash_map.hpp"
#include "mlmap/scan.hpp"

namespace mlmap::registration {

struct SequenceConfig {
  IcpConfig icp{.initial_max_distance = 0.5};  // a lower bound: the basin sets the first gate
  BasinConfig basin;                 // the start's error bound, verification, retries
  double source_voxel_size = 0.1;    // m, down-sampling of the scan being registered
  double map_voxel_size = 0.1;       // m, OcTree resolution of the map's key grid
  std::size_t max_points_per_voxel = 20;
  NormalConfig normals;
  double min_range = 0.1;            // m, closer points (the robot itself) are dropped
  double max_range = 30.0;           // m, farther points are dropped
  // Global refinement.
  double max_pair_distance = 5.0;    // m, sensor positions farther apart form no pair
  double min_overlap = 0.5;          // fraction of a scan's points that must find a partner
  int refinement_rounds = 2;         // pairwise ICP + pose graph, each from the last poses
  // The scan-to-map result links consecutive scans in the graph with this uncertainty: it
  // keeps the graph connected and holds what no scan pair observes (along a corridor).
  double chain_sigma_translation = 0.02;  // m
  double chain_sigma_rotation = 0.002;    // rad
};

struct RefinementResult {
  std::size_t pair_edges = 0;        // verified ICP edges in the last round
  std::size_t loop_edges = 0;        // ... of them between scans that are not consecutive
  std::size_t rejected_pairs = 0;    // candidate pairs not verified (too little overlap, not explained)
  PoseGraphResult graph;             // of the last round
  // The pose graph's poses are kept only when they lower the scans' residuals against each
  // other (the mean truncated squared point-to-plane residual over the verified pairs, m²):
  // refinement never makes a sequence worse than scan-to-map.
  double residual_before = 0.0;
  double residual_after = 0.0;
  int rounds_applied = 0;
};

class SequenceRegistration {
 public:
  explicit SequenceRegistration(const SequenceConfig& config = {});

  // Registers `points` (sensor frame) against the map of the scans so far, starting from
  // the last corrected pose moved by the odometry increment (alignVerified: wide basin,
  // verification, retries), and adds it to the map. The first scan stays at its odometry
  // pose and anchors the map. Returns the result (for the first scan an empty, verified one).
  VerifiedIcp addScan(const std::vector<Point>& points, const Pose& odometry);

  // Pairwise ICP between scans whose sensors are within max_pair_distance (consecutive or
  // not: loop closures), then a pose graph with the verified pairs, weighted by their
  // normal equations, and the scan-to-map chain; refines poses() in place where that lowers
  // the residuals.
  RefinementResult refine();

  const std::vector<Pose>& poses() const { return poses_; }
  const SequenceConfig& config() const { return config_; }

 private:
  // The mean truncated squared point-to-plane residual of the pairs' scans at `poses`.
  double pairResidual(const std::vector<std::pair<std::size_t, std::size_t>>& pairs, const std::vector<Pose>& poses,
                      const std::vector<VoxelHashMap>& locals, const std::vector<double>& noise,
                      const std::vector<double>& source_noise) const;

  SequenceConfig config_;
  VoxelHashMap map_;
  std::vector<Pose> odometry_;
  std::vector<Pose> poses_;
  std::vector<Pose> chain_;                  // the scan-to-map poses, before refinement
  std::vector<std::vector<Point>> sources_;  // sensor frame, down-sampled at source_voxel_size
  std::vector<std::vector<Point>> dense_;    // sensor frame, down-sampled at map_voxel_size / 2
};

}  // namespace mlmap::registration
