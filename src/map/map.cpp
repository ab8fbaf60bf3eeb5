#include "mlmap/map/map.hpp"

#include <cmath>
#include <string>
#include <vector>

#include "mlmap/error.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap {
namespace {

MapConfig resolved(MapConfig config) {
  if (config.octree_resolution <= 0.0) config.octree_resolution = config.cell_size;
  return config;
}

struct RayKeys {
  octomap::KeySet free;
  octomap::KeySet occupied;
};

// The keys one scan frees and occupies, like OcTree::computeUpdate but over all
// cores: ray casting is the expensive part and only reads the tree's geometry.
RayKeys computeRayKeys(const octomap::OcTree& tree, const Scan& scan, double max_range) {
  RayKeys result;
  const Eigen::Vector3d origin_eigen = scan.pose.translation();
  const octomap::point3d origin(static_cast<float>(origin_eigen.x()),
                                static_cast<float>(origin_eigen.y()),
                                static_cast<float>(origin_eigen.z()));
  const auto point_count = static_cast<std::int64_t>(scan.size());
#pragma omp parallel
  {
    RayKeys local;
    octomap::KeyRay ray;
#pragma omp for schedule(static)
    for (std::int64_t index = 0; index < point_count; ++index) {
      const Eigen::Vector3d world = scan.worldPoint(static_cast<std::size_t>(index));
      octomap::point3d end(static_cast<float>(world.x()), static_cast<float>(world.y()),
                           static_cast<float>(world.z()));
      bool hit = true;
      if (max_range > 0.0 && (end - origin).norm() > max_range) {
        end = origin + (end - origin).normalized() * static_cast<float>(max_range);
        hit = false;
      }
      if (tree.computeRayKeys(origin, end, ray)) local.free.insert(ray.begin(), ray.end());
      octomap::OcTreeKey key;
      if (hit && tree.coordToKeyChecked(end, key)) local.occupied.insert(key);
    }
#pragma omp critical(mlmap_octree_merge)
    {
      result.free.insert(local.free.begin(), local.free.end());
      result.occupied.insert(local.occupied.begin(), local.occupied.end());
    }
  }
  return result;
}

}  // namespace

Map::Map(const MapConfig& config) : config_(resolved(config)), blocks_(config_.cell_size) {
  if (config_.with_octree) {
    if (!(config_.octree_resolution > 0.0) || !std::isfinite(config_.octree_resolution)) {
      throw Error("octree resolution must be positive");
    }
    octree_ = std::make_unique<octomap::OcTree>(config_.octree_resolution);
  }
}

void Map::insertScan(const Scan& scan) {
  insertIntoBlocks(scan);
  insertIntoOctree(scan);
}

void Map::insertIntoBlocks(const Scan& scan) {
  if (planes_) clearPlanes();
  blocks_.insertScan(scan);
}

void Map::clearPlanes() {
  planes_.reset();
  for (std::size_t n = 0; n < blocks_.cellCount(); ++n) {
    for (Block& block : blocks_.mutableBlocksAt(n)) block.plane = 0;
  }
}

void Map::insertIntoOctree(const Scan& scan) {
  if (!octree_) return;
  const RayKeys keys = computeRayKeys(*octree_, scan, config_.max_range);
  // A voxel both crossed and hit in one scan counts as hit, as in OctoMap.
  for (const octomap::OcTreeKey& key : keys.free) {
    if (keys.occupied.find(key) == keys.occupied.end()) octree_->updateNode(key, false, true);
  }
  for (const octomap::OcTreeKey& key : keys.occupied) octree_->updateNode(key, true, true);
  octree_->updateInnerOccupancy();
}

void Map::compact() {
  blocks_.compact();
  if (octree_) octree_->prune();
}

void Map::setOctree(std::unique_ptr<octomap::OcTree> octree) {
  if (octree && std::abs(octree->getResolution() - config_.octree_resolution) > 1e-9) {
    throw Error("OcTree resolution " + std::to_string(octree->getResolution()) +
                " differs from the map's " + std::to_string(config_.octree_resolution));
  }
  octree_ = std::move(octree);
  config_.with_octree = octree_ != nullptr;
}

}  // namespace mlmap
