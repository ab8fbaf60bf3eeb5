#include "mlmap/io/octree_export.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "captured_cerr.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/atomic_file.hpp"
#include "mlmap/io/palette.hpp"
#include "mlmap/map/surface_points.hpp"
#include "../map/leaf_voxels.hpp"
#include "occupied_voxels.hpp"

namespace mlmap::io {
namespace {

// The plane label of the block a voxel lies in: the block nearest in height among
// the cells under the voxel's footprint, within a cell of its extent.
std::int32_t planeAt(const MLMap& blocks, const Eigen::Vector3d& centre, double voxel_size) {
  const double cell_size = blocks.cellSize();
  const double half = std::max(voxel_size, cell_size) / 2.0;
  const double reach = std::max(voxel_size / 2.0, cell_size);
  std::int32_t label = 0;
  double best = std::numeric_limits<double>::infinity();
  // At most 2 x 2 samples of the footprint: enough to reach a wall's cells when the
  // voxel is coarser than the cells.
  const double step = std::max(cell_size, half);
  for (double dy = -half + step / 2.0; dy < half; dy += step) {
    for (double dx = -half + step / 2.0; dx < half; dx += step) {
      const auto cell = blocks.findCellOf(centre.x() + dx, centre.y() + dy);
      if (!cell) continue;
      for (const Block& block : blocks.blocks(*cell)) {
        const double below = block.bottom() - centre.z();
        const double above = centre.z() - block.height;
        const double gap = std::max({below, above, 0.0});
        // Labelled blocks win ties: a wall voxel at a floor's edge shows the wall.
        const double score = gap - (block.plane != 0 ? 1e-6 : 0.0);
        if (gap <= reach && score < best) {
          best = score;
          label = block.plane;
        }
      }
    }
  }
  return label;
}

octomap::point3d toPoint3d(const Eigen::Vector3d& point) {
  return {static_cast<float>(point.x()), static_cast<float>(point.y()), static_cast<float>(point.z())};
}

// The centre as OctoMap holds it (single precision), so the plane is looked up where the
// ColorOcTree puts the voxel, exactly as before this was shared with the dashboard.
Eigen::Vector3d toPoint3dPrecision(const Eigen::Vector3d& point) { return point.cast<float>().cast<double>(); }

void addVoxel(octomap::ColorOcTree& tree, const octomap::point3d& centre, float log_odds, std::int32_t plane) {
  octomap::OcTreeKey key;
  if (!tree.coordToKeyChecked(centre, key)) return;
  tree.setNodeValue(key, log_odds, true);
  const Rgb colour = planeColour(plane);
  tree.setNodeColor(key, colour.red, colour.green, colour.blue);
}

}  // namespace

double occupiedVoxelSize(const Map& map) {
  return map.hasOctree() ? map.octree().getResolution() : map.config().cell_size;
}

void forEachOccupiedVoxel(const Map& map, const std::function<void(const Eigen::Vector3d&, float, std::int32_t)>& visit) {
  const double resolution = occupiedVoxelSize(map);
  if (map.hasOctree()) {
    const octomap::OcTree& source = map.octree();
    for (auto leaf = source.begin_leafs(), end = source.end_leafs(); leaf != end; ++leaf) {
      if (!source.isNodeOccupied(*leaf)) continue;
      const float log_odds = leaf->getLogOdds();
      forEachVoxelOfLeaf(leaf, resolution, [&](const Eigen::Vector3d& corner) {
        const Eigen::Vector3d centre = toPoint3dPrecision(corner + Eigen::Vector3d::Constant(resolution / 2.0));
        visit(centre, log_odds, planeAt(map.blocks(), centre, resolution));
      });
    }
  } else {
    // A map without an OcTree: voxels from its blocks at the cell size.
    const float occupied = octomap::ColorOcTree(resolution).getClampingThresMaxLog();
    for (const Point& point : blockSurfacePoints(map.blocks(), resolution)) {
      const Eigen::Vector3d centre = toPoint3dPrecision(point.cast<double>());
      visit(centre, occupied, planeAt(map.blocks(), centre, resolution));
    }
  }
}

std::unique_ptr<octomap::ColorOcTree> colouredOctree(const Map& map) {
  auto tree = std::make_unique<octomap::ColorOcTree>(occupiedVoxelSize(map));
  forEachOccupiedVoxel(map, [&tree](const Eigen::Vector3d& centre, float log_odds, std::int32_t plane) {
    addVoxel(*tree, toPoint3d(centre), log_odds, plane);
  });
  // Inner nodes get their children's maximum occupancy and mean colour, so octovis
  // shows coarser levels of detail in the right colours.
  tree->updateInnerOccupancy();
  return tree;
}

void writeColouredOctree(const std::filesystem::path& path, const Map& map) {
  const std::unique_ptr<octomap::ColorOcTree> tree = colouredOctree(map);
  writeAtomically(path, [&](std::ostream& out) {
    const CapturedCerr quiet;
    if (!tree->write(out)) throw Error("OctoMap could not write the ColorOcTree");
  });
}

void writeBinaryOctree(const std::filesystem::path& path, const Map& map) {
  if (!map.hasOctree()) throw Error(path.string() + ": the map has no OcTree (it was built with --no-octree)");
  // A .bt holds two bits a node, occupied or free: the maximum-likelihood tree, whose
  // leaves of one state merge once pruned (as OctoMap's own writeBinary does, here on a
  // copy: the map keeps its log-odds). Unpruned it was 1.84x the size of OctoMap's.
  octomap::OcTree tree(map.octree());
  tree.toMaxLikelihood();
  tree.prune();
  writeAtomically(path, [&](std::ostream& out) {
    const CapturedCerr quiet;
    if (!tree.writeBinaryConst(out)) throw Error("OctoMap could not write the OcTree");
  });
}

}  // namespace mlmap::io
