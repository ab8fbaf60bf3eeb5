#include "mlmap/map/merge.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <unordered_set>
#include <vector>

#include "leaf_voxels.hpp"
#include "mlmap/error.hpp"

namespace mlmap {
namespace {

std::uint64_t packCell(CellIndex cell) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(cell.i)) << 32) |
         static_cast<std::uint32_t>(cell.j);
}

CellIndex unpackCell(std::uint64_t packed) {
  return {static_cast<std::int32_t>(static_cast<std::uint32_t>(packed >> 32)),
          static_cast<std::int32_t>(static_cast<std::uint32_t>(packed))};
}

}  // namespace

Eigen::Isometry3d levelledTransform(const Eigen::Isometry3d& transform, double& tilt_deg) {
  const Eigen::Vector3d up = transform.linear() * Eigen::Vector3d::UnitZ();
  tilt_deg = std::acos(std::clamp(up.z(), -1.0, 1.0)) * 180.0 / std::numbers::pi;
  const Eigen::Vector3d forward = transform.linear() * Eigen::Vector3d::UnitX();
  const double yaw = std::atan2(forward.y(), forward.x());
  Eigen::Isometry3d result = Eigen::Isometry3d::Identity();
  result.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  result.translation() = transform.translation();
  return result;
}

namespace {

void mergeBlocks(MLMap& base, const MLMap& other, const Eigen::Isometry3d& other_to_base) {
  // Pull resampling: every base cell whose centre falls inside an other cell takes
  // that cell's blocks once. Such base cells lie within one cell of where the other
  // cell's centre lands, so the 3 x 3 neighbourhood of each landing cell is searched.
  std::unordered_set<std::uint64_t> targets;
  for (std::size_t n = 0; n < other.cellCount(); ++n) {
    if (other.blocksAt(n).empty()) continue;
    const Eigen::Vector2d centre = other.cellCenter(other.cellAt(n));
    const Eigen::Vector3d moved = other_to_base * Eigen::Vector3d(centre.x(), centre.y(), 0.0);
    const CellIndex landing = base.cellOf(moved.x(), moved.y());
    for (int di = -1; di <= 1; ++di) {
      for (int dj = -1; dj <= 1; ++dj) targets.insert(packCell({landing.i + di, landing.j + dj}));
    }
  }
  // Sorted, so the merged map does not depend on the hash set's order.
  std::vector<std::uint64_t> ordered(targets.begin(), targets.end());
  std::sort(ordered.begin(), ordered.end());
  const Eigen::Isometry3d base_to_other = other_to_base.inverse();
  const auto height_shift = static_cast<float>(other_to_base.translation().z());
  // Blocks only turn about z (the transform was levelled): the points' moments turn
  // with them, and their mean is then taken from the target cell's centre.
  const double yaw = std::atan2(other_to_base.linear()(1, 0), other_to_base.linear()(0, 0));
  for (const std::uint64_t packed : ordered) {
    const CellIndex target = unpackCell(packed);
    const Eigen::Vector2d centre = base.cellCenter(target);
    const Eigen::Vector3d source_point = base_to_other * Eigen::Vector3d(centre.x(), centre.y(), 0.0);
    const auto source = other.findCellOf(source_point.x(), source_point.y());
    if (!source) continue;
    const Eigen::Vector2d source_centre = other.cellCenter(*source);
    const Eigen::Vector3d moved_centre = other_to_base * Eigen::Vector3d(source_centre.x(), source_centre.y(), 0.0);
    for (Block block : other.blocks(*source)) {
      block.height += height_shift;
      block.plane = 0;
      block.points = block.points.turned(yaw, height_shift).shifted(centre.x() - moved_centre.x(), centre.y() - moved_centre.y());
      base.insertBlock(target, block);
    }
  }
}

// Adds the other tree's log-odds to the base tree, voxel by voxel. Occupied voxels
// are sampled at their 8 octant centres so a turned wall keeps no holes; free space,
// which is most of the volume, is moved by its centre only.
std::size_t fuseOctrees(octomap::OcTree& base, const octomap::OcTree& other, const Eigen::Isometry3d& other_to_base) {
  const double resolution = other.getResolution();
  const bool pure_translation = other_to_base.linear().isIdentity(1e-12);
  std::size_t updates = 0;
  std::vector<octomap::OcTreeKey> keys;
  for (auto leaf = other.begin_leafs(), end = other.end_leafs(); leaf != end; ++leaf) {
    const float log_odds = leaf->getLogOdds();
    const bool occupied = other.isNodeOccupied(*leaf);
    const int samples = occupied && !pure_translation ? 2 : 1;
    forEachVoxelOfLeaf(leaf, resolution, [&](const Eigen::Vector3d& corner) {
      keys.clear();
      for (int sa = 0; sa < samples; ++sa) {
        for (int sb = 0; sb < samples; ++sb) {
          for (int sc = 0; sc < samples; ++sc) {
            const Eigen::Vector3d sample = corner + resolution / samples * Eigen::Vector3d(sa + 0.5, sb + 0.5, sc + 0.5);
            const Eigen::Vector3d moved = other_to_base * sample;
            octomap::OcTreeKey key;
            if (base.coordToKeyChecked(moved.x(), moved.y(), moved.z(), key) &&
                std::find(keys.begin(), keys.end(), key) == keys.end()) {
              keys.push_back(key);
            }
          }
        }
      }
      for (const octomap::OcTreeKey& key : keys) base.updateNode(key, log_odds, true);
      updates += keys.size();
    });
  }
  base.updateInnerOccupancy();
  base.prune();
  return updates;
}

}  // namespace

MergeStats mergeInto(Map& base, const Map& other, const Eigen::Isometry3d& other_to_base, double max_tilt_deg) {
  if (std::abs(base.config().cell_size - other.config().cell_size) > 1e-9) {
    throw Error("cannot merge maps of different cell sizes (" + std::to_string(base.config().cell_size) + " m and " +
                std::to_string(other.config().cell_size) + " m): build them with the same --cell-size");
  }
  if (base.hasOctree() != other.hasOctree()) {
    throw Error("cannot merge a map with an OcTree and one without: build both with or both without --no-octree");
  }
  if (base.hasOctree() && std::abs(base.octree().getResolution() - other.octree().getResolution()) > 1e-9) {
    throw Error("cannot merge OcTrees of different resolutions: build both with the same --octree-resolution");
  }
  MergeStats stats;
  const Eigen::Isometry3d transform = levelledTransform(other_to_base, stats.dropped_tilt_deg);
  if (stats.dropped_tilt_deg > max_tilt_deg) {
    throw Error("the transform tilts the other map by " + std::to_string(stats.dropped_tilt_deg) +
                "°: ML maps are gravity-aligned, only yaw and translation can be merged (limit " +
                std::to_string(max_tilt_deg) + "°)");
  }
  stats.base_blocks = base.blocks().blockCount();
  stats.other_blocks = other.blocks().blockCount();
  stats.base_cells = base.blocks().stats().cells;
  stats.other_cells = other.blocks().stats().cells;
  base.clearPlanes();
  mergeBlocks(base.blocks(), other.blocks(), transform);
  if (base.hasOctree()) stats.fused_voxels = fuseOctrees(base.octree(), other.octree(), transform);
  base.blocks().compact();
  stats.merged_blocks = base.blocks().blockCount();
  stats.merged_cells = base.blocks().stats().cells;
  return stats;
}

}  // namespace mlmap
