// The Map: the ML-map block layer (eRMSM's input) beside an octomap::OcTree that
// handles occupancy and map fusion. Both layers see the same scans.
#pragma once

#include <memory>
#include <optional>

#include <octomap/OcTree.h>

#include "mlmap/map/ml_map.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "mlmap/scan.hpp"

namespace mlmap {

struct MapConfig {
  double cell_size = 0.1;           // m, ML-map resolution (section IV's cell_size)
  double octree_resolution = 0.0;   // m, OcTree voxel size; 0 = same as cell_size
  double max_range = -1.0;          // m, rays are cut here for the OcTree; < 0 = no limit
  bool with_octree = true;          // false builds the block layer only
  // OcTree rays: false = one ray per voxel holding end points, to its centre (OctoMap's
  // insertPointCloud with discretize = true); true = one ray per point (discretize = false).
  bool exact_rays = false;
  // m: where the map's frame has its origin in the world (the scans' poses' frame). The map
  // holds its points moved by −origin: a cloud in a national grid's coordinates (x 500 km,
  // y 5,000 km) lies beyond the OcTree's keys (±32,768 voxels) and rounds in the blocks'
  // float, so `mlmap build` moves it near the origin (chooseOrigin) and the commands give
  // planes and points back in the world's coordinates. Zero for maps near the origin.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
};

class Map {
 public:
  explicit Map(const MapConfig& config = {});

  // Adds a scan to both layers: its points to the blocks, its rays (from the sensor
  // origin, clearing free space) to the OcTree.
  void insertScan(const Scan& scan);
  void insertIntoBlocks(const Scan& scan);
  void insertIntoOctree(const Scan& scan);

  // Releases build-time slack: packs the blocks and prunes the OcTree.
  void compact();

  const MapConfig& config() const { return config_; }
  // Sets MapConfig::origin; only before any scan was inserted (throws mlmap::Error after).
  void setOrigin(const Eigen::Vector3d& origin);
  const MLMap& blocks() const { return blocks_; }
  MLMap& blocks() { return blocks_; }
  bool hasOctree() const { return octree_ != nullptr; }
  const octomap::OcTree& octree() const { return *octree_; }
  octomap::OcTree& octree() { return *octree_; }

  // Replaces the OcTree (map readers); its resolution must match the config's.
  void setOctree(std::unique_ptr<octomap::OcTree> octree);

  // The planes its blocks' labels refer to, once detected (mlmap planes). Kept with
  // the map so exports need no second detection run.
  const std::optional<PlaneDetection>& planes() const { return planes_; }
  void setPlanes(PlaneDetection planes) { planes_ = std::move(planes); }
  // Forgets the planes and clears every block's label: blocks that changed (new
  // scans, a merge) would otherwise carry labels of planes no longer there.
  void clearPlanes();

 private:
  MapConfig config_;
  MLMap blocks_;
  std::unique_ptr<octomap::OcTree> octree_;
  std::optional<PlaneDetection> planes_;
};

}  // namespace mlmap
