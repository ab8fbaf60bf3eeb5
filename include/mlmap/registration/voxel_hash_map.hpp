// Nearest neighbours through the OcTree key grid: the points of a map bucketed by
// octomap::OcTreeKey at the map resolution (a voxel hash, like KISS-ICP's VoxelHashMap).
// A query visits only the voxels its search sphere's bounding box overlaps, nearest
// first, and skips voxels farther than the best point found so far.
#pragma once

#include <octomap/OcTree.h>

#include <cstddef>
#include <optional>
#include <unordered_map>
#include <vector>

#include "mlmap/scan.hpp"

namespace mlmap::registration {

using Normal = Eigen::Vector3d;

struct Neighbour {
  Point point;            // m, map frame
  Normal normal;          // unit; zero where the neighbourhood is not planar or not estimated
  double distance = 0.0;  // m, from the query
};

struct NormalConfig {
  double radius = 0.2;             // m, PCA neighbourhood of a voxel's centroid
  std::size_t min_neighbours = 6;  // fewer leaves the normal zero
  double max_curvature = 0.05;     // λ_min / (λ0 + λ1 + λ2) above this: not planar, zero normal
};

class VoxelHashMap {
 public:
  // `voxel_size` is the OcTree resolution of the key grid; each voxel keeps its first
  // `max_points_per_voxel` points, so the map stays down-sampled however often a
  // surface is seen.
  explicit VoxelHashMap(double voxel_size, std::size_t max_points_per_voxel = 20);

  // Points outside the OcTree's key range (±32768 voxels) are skipped.
  void addPoints(const std::vector<Point>& points);
  // One normal per voxel: PCA over the points within config.radius of the voxel's
  // centroid, for the voxels that gained points since the last call.
  void estimateNormals(const NormalConfig& config = {});

  // The nearest point within `max_distance` of `query`, if any.
  std::optional<Neighbour> nearest(const Point& query, double max_distance) const;
  // Every point within `radius` of `query`, in no particular order.
  std::vector<Point> within(const Point& query, double radius) const;

  std::vector<Point> points() const;
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  std::size_t voxelCount() const { return voxels_.size(); }
  double voxelSize() const { return key_grid_.getResolution(); }

 private:
  struct Voxel {
    std::vector<Point> points;
    Normal normal = Normal::Zero();  // shared by the voxel's points
    bool dirty = false;              // gained points since the last estimateNormals()
  };
  template <typename Visit>
  void visitVoxels(const Point& query, double radius, Visit&& visit) const;

  octomap::OcTree key_grid_;  // stays empty: its coordToKey defines the voxels
  std::size_t max_points_per_voxel_;
  std::size_t size_ = 0;
  std::unordered_map<octomap::OcTreeKey, Voxel, octomap::OcTreeKey::KeyHash> voxels_;
};

}  // namespace mlmap::registration
