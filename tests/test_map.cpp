// The Map: the block layer and the OcTree see the same scans; rays clear free space.
#include <doctest/doctest.h>

#include "mlmap/map/map.hpp"

using namespace mlmap;

namespace {

// A wall at x = 2 seen from the origin at 1 m height: a fan of rays.
Scan wallScan() {
  Scan scan;
  scan.pose.translation() = Eigen::Vector3d(0.0, 0.0, 1.0);
  for (double y = -1.0; y <= 1.0; y += 0.02) {
    for (double z = -0.9; z <= 0.9; z += 0.02) scan.points.emplace_back(2.0, y, z);
  }
  return scan;
}

}  // namespace

TEST_CASE("Map: one scan reaches both layers, the OcTree at the cell size") {
  MapConfig config;
  config.cell_size = 0.1;
  Map map(config);
  map.insertScan(wallScan());
  CHECK(map.octree().getResolution() == doctest::Approx(0.1));
  // Blocks: one vertical block per cell of the wall's column.
  const auto blocks = map.blocks().blocks(map.blocks().cellOf(2.05, 0.05));
  REQUIRE(blocks.size() == 1);
  CHECK(blocks[0].isVertical());
  CHECK(blocks[0].bottom() == doctest::Approx(0.1).epsilon(0.01));
  CHECK(blocks[0].height == doctest::Approx(1.9).epsilon(0.01));
  // OcTree: the wall occupied, the space the rays crossed free, the space behind unknown.
  const auto& tree = map.octree();
  const auto* wall = tree.search(2.01, 0.0, 1.0);
  REQUIRE(wall != nullptr);
  CHECK(tree.isNodeOccupied(wall));
  const auto* between = tree.search(1.0, 0.0, 1.0);
  REQUIRE(between != nullptr);
  CHECK_FALSE(tree.isNodeOccupied(between));
  CHECK(tree.search(3.0, 0.0, 1.0) == nullptr);
}

TEST_CASE("Map: rays cut at max_range clear free space but mark nothing occupied") {
  MapConfig config;
  config.cell_size = 0.1;
  config.max_range = 1.0;
  Map map(config);
  map.insertScan(wallScan());
  const auto& tree = map.octree();
  const auto* near = tree.search(0.5, 0.0, 1.0);
  REQUIRE(near != nullptr);
  CHECK_FALSE(tree.isNodeOccupied(near));
  CHECK(tree.search(2.01, 0.0, 1.0) == nullptr);
  // The block layer still takes every point.
  CHECK(map.blocks().blockCount() > 0);
}

TEST_CASE("Map: a block-only map has no OcTree, compact keeps both layers' content") {
  MapConfig config;
  config.with_octree = false;
  Map blocks_only(config);
  blocks_only.insertScan(wallScan());
  CHECK_FALSE(blocks_only.hasOctree());
  Map both(MapConfig{});
  both.insertScan(wallScan());
  const std::size_t leaves_before = both.octree().getNumLeafNodes();
  const std::size_t blocks_before = both.blocks().blockCount();
  both.compact();
  CHECK(both.blocks().blockCount() == blocks_before);
  CHECK(both.octree().getNumLeafNodes() <= leaves_before);
  CHECK(blocks_only.blocks().blockCount() == blocks_before);
}
