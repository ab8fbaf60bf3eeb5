#include "mlmap/map/map.hpp"

#include <cmath>
#include <string>

#include "mlmap/error.hpp"
#include "octree_update.hpp"

namespace mlmap {
namespace {

MapConfig resolved(MapConfig config) {
  if (config.octree_resolution <= 0.0) config.octree_resolution = config.cell_size;
  return config;
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
  detail::insertRays(*octree_, scan, {config_.max_range, config_.exact_rays});
}

void Map::setOrigin(const Eigen::Vector3d& origin) {
  if (blocks_.blockCount() > 0 || (octree_ && octree_->size() > 0))
    throw Error("the map's origin can only be set before its first scan");
  if (!origin.allFinite()) throw Error("the map's origin must be a finite point");
  config_.origin = origin;
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
