// Nearest neighbours through the OcTree key grid: the points of a map bucketed by their
// octomap::OcTreeKey at the map resolution, i.e. floor(c / resolution) (a voxel hash, like
// KISS-ICP's VoxelHashMap), in a flat VoxelTable. A query visits only the voxels its search
// sphere's bounding box overlaps, nearest first, and skips voxels farther than the best
// point found so far; a wide search (a gate of decimetres to metres, far beyond the voxel)
// visits blocks of 4³ voxels instead and looks only into the occupied ones, so a query that
// finds nothing costs the blocks its sphere overlaps, not every voxel. A query whose own
// voxel is empty goes by those blocks too, and one that finds a point within a voxel looks
// only at the neighbours in reach. Each voxel keeps the moments of its points, so a normal is a sum of a
// few neighbouring voxels' moments and one 3×3 eigen-decomposition, not a radius search.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "mlmap/registration/voxel_table.hpp"
#include "mlmap/scan.hpp"

namespace mlmap::registration {

using Normal = Eigen::Vector3d;

struct Neighbour {
  Point point;            // m, map frame
  Normal normal;          // unit; zero where the neighbourhood is not planar or not estimated
  double distance = 0.0;  // m, from the query
};

struct NormalConfig {
  double radius = 0.2;             // m, PCA over the voxels whose centres lie this close to the voxel's
  std::size_t min_neighbours = 6;  // fewer leaves the normal zero
  double max_curvature = 0.05;     // λ_min / (λ0 + λ1 + λ2) above this: not planar, zero normal
  // m; where the neighbourhood within `radius` is too sparse for a plane (fewer than
  // min_neighbours points, or points along one scan line only), the radius doubles up to this
  // (like a k-nearest-neighbour normal, which reaches as far as the sampling needs). A far
  // surface is sampled at range × the scan's angular step: the stress benchmark's long
  // corridor's end wall, 20-26 m away at 1 deg between lines, holds points 0.35-0.45 m apart,
  // and it is the only surface there facing the corridor's axis: 4 × the radius (two
  // doublings) gives it normals (60 of 60 and 81 of 88 of its points in the map, none at
  // 0.2 m; at 0.4 m 0 to 50). At most `radius`: no growth.
  double max_radius = 0.0;
};

class VoxelHashMap {
 public:
  // `voxel_size` is the OcTree resolution of the key grid; each voxel keeps its first
  // `max_points_per_voxel` points, so the map stays down-sampled however often a
  // surface is seen.
  explicit VoxelHashMap(double voxel_size, std::size_t max_points_per_voxel = 20);

  // Points outside the OcTree's key range (±32768 voxels) are skipped.
  void addPoints(const std::vector<Point>& points);
  // One normal per voxel: PCA over the points of the voxels whose centres lie within
  // config.radius of its centre (doubled up to config.max_radius where that is too sparse),
  // for the voxels whose neighbourhood gained points since the last call and those whose
  // last normal needed a wider neighbourhood.
  void estimateNormals(const NormalConfig& config = {});

  // The nearest point within `max_distance` of `query`, if any.
  std::optional<Neighbour> nearest(const Point& query, double max_distance) const;
  // Every point within `radius` of `query`, in no particular order.
  std::vector<Point> within(const Point& query, double radius) const;

  // The noise of the map's surfaces as ICP meets them, m: the robust (MAD) spread of the
  // points' distances from their neighbourhood's plane (the points of the voxels whose
  // centres lie within the last estimateNormals() radius, the voxel's normal through their
  // mean), scaled for the plane's 3 fitted degrees of freedom; over at most `max_voxels`
  // voxels with a normal, spread evenly; 0 when none qualifies. The neighbourhood, not the
  // voxel alone: a voxel's few points share its bias (down-sampled centroids, points split
  // by a voxel boundary near the surface), which its neighbours do not (the simulated lab:
  // 0.21 cm within voxels, 0.47 cm about the neighbourhood, residuals at the true pose 0.62 cm).
  double surfaceNoise(std::size_t max_voxels = 4000) const;

  std::vector<Point> points() const;
  std::size_t size() const { return points_.size(); }
  bool empty() const { return points_.empty(); }
  std::size_t voxelCount() const { return table_.size(); }
  double voxelSize() const { return voxel_size_; }

 private:
  // Moments of a voxel's points about its centre (not the origin: precision far from it).
  struct Moments {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();    // Σ d, d = p − centre
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();  // Σ d dᵀ
  };
  template <typename Visit>
  void visitVoxels(const Point& query, double radius, Visit&& visit) const;
  template <typename Visit>
  void visitBlocks(const Point& query, double radius, Visit&& visit) const;
  void indexBlocks();
  Point centreOf(const VoxelKey& key) const;
  std::size_t pointsIn(std::size_t voxel) const { return begin_[voxel + 1] - begin_[voxel]; }

  double voxel_size_;
  double inverse_size_;
  std::size_t max_points_per_voxel_;
  // Per voxel, in insertion order (the table maps a key to its index and back). A query
  // touches only the table, begin_ and points_: the points of all voxels packed in one array,
  // voxel by voxel, so a voxel's points are one contiguous read.
  VoxelTable table_;
  std::vector<std::uint32_t> begin_{0};  // voxel v holds points_[begin_[v], begin_[v + 1])
  std::vector<Point> points_;
  std::vector<Normal> normals_;          // shared by the voxel's points
  std::vector<Moments> moments_;
  std::vector<char> dirty_;              // gained points since the last estimateNormals()
  std::vector<char> sparse_;             // its normal needed (or lacked) a wider neighbourhood
  std::vector<VoxelKey> stencil_;        // the neighbourhood of the last estimateNormals()
  // Blocks of 4³ voxels (keys shifted right by 2): which voxels each holds, packed block by
  // block like the points (block b: block_voxels_[block_begin_[b], block_begin_[b + 1])).
  VoxelTable blocks_;
  std::vector<std::uint32_t> voxel_block_;  // per voxel, its block's index
  std::vector<std::uint32_t> block_begin_{0};
  std::vector<std::uint32_t> block_voxels_;
  // The keys of block_voxels_, packed the same way: a wide search reads a block's voxels'
  // keys in one run instead of one table entry each.
  std::vector<VoxelKey> block_voxel_keys_;
  // Per block, the box of its points (m): on a surface much thinner than the block, so a
  // wide search passes by the blocks beside it whose points lie beyond its radius.
  std::vector<Eigen::Vector3d> block_low_;
  std::vector<Eigen::Vector3d> block_high_;
};

}  // namespace mlmap::registration
