// Exports of a labelled map: the ColorOcTree read back through OctoMap's factory with
// the colours of known planes, the blocks PLY, the .bt, the palette, atomic failure.
#include <doctest/doctest.h>

#include <fstream>
#include <set>
#include <sstream>

#include <octomap/AbstractOcTree.h>

#include "helpers.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/block_ply.hpp"
#include "mlmap/io/dashboard_voxels.hpp"
#include "mlmap/io/octree_export.hpp"
#include "mlmap/io/palette.hpp"
#include "mlmap/io/ply.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"
#include "room_scenes.hpp"

using namespace mlmap;

namespace {

// The L-shaped rooms, all scans at their true poses, planes detected.
Map labelledRooms(bool with_octree) {
  Map map(MapConfig{0.05, 0.0, 12.0, with_octree});
  for (const sim::SimulatedScan& scan : sim::simulate(sim::parseScene(mlmap::test::kRoomsJson, "rooms.json"))) {
    map.insertScan(scan.scan);
  }
  map.compact();
  map.setPlanes(detectPlanes(map.blocks()));
  return map;
}

// A labelled block's point (cell centre at h, or mid-height) and label, the first
// found whose point satisfies `where` (the scans are sparse: not every cell has blocks).
template <typename Where>
std::pair<Eigen::Vector3d, std::int32_t> labelledBlock(const Map& map, Where&& where) {
  const MLMap& blocks = map.blocks();
  for (std::size_t n = 0; n < blocks.cellCount(); ++n) {
    const Eigen::Vector2d xy = blocks.cellCenter(blocks.cellAt(n));
    for (const Block& block : blocks.blocksAt(n)) {
      const Eigen::Vector3d point(xy.x(), xy.y(), block.height - block.depth / 2.0);
      if (block.plane > 0 && where(point, block)) return {point, block.plane};
    }
  }
  FAIL("no labelled block where expected");
  return {};
}

// The colour of the occupied voxel nearest to `point` along `axis` (a surface's voxel
// may lie either side of it).
std::optional<io::Rgb> voxelColour(const octomap::ColorOcTree& tree, Eigen::Vector3d point, const Eigen::Vector3d& axis) {
  for (const double shift : {0.0, -0.03, 0.03, -0.06, 0.06}) {
    const Eigen::Vector3d probe = point + shift * axis;
    const octomap::ColorOcTreeNode* node = tree.search(probe.x(), probe.y(), probe.z());
    if (node != nullptr && tree.isNodeOccupied(node)) {
      const octomap::ColorOcTreeNode::Color colour = node->getColor();
      return io::Rgb{colour.r, colour.g, colour.b};
    }
  }
  return std::nullopt;
}

}  // namespace

TEST_CASE("Export: the ColorOcTree reads back through AbstractOcTree::read with each plane's colour") {
  const test::TempDir dir;
  const Map map = labelledRooms(true);
  io::writeColouredOctree(dir / "rooms.ot", map);

  std::ifstream in(dir / "rooms.ot", std::ios::binary);
  std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(in));
  REQUIRE(tree != nullptr);
  const auto* coloured = dynamic_cast<const octomap::ColorOcTree*>(tree.get());
  REQUIRE(coloured != nullptr);
  CHECK(coloured->getResolution() == doctest::Approx(0.05));

  const auto [floor_point, floor] = labelledBlock(map, [](const Eigen::Vector3d& p, const Block& b) {
    return !b.isVertical() && std::abs(p.z()) < 0.03 && p.x() > 1.0 && p.x() < 2.5 && p.y() > 2.0 && p.y() < 3.5;
  });
  const auto [east_point, east_wall] = labelledBlock(map, [](const Eigen::Vector3d& p, const Block& b) {
    return b.isVertical() && p.x() > 7.95 && p.y() > 2.0 && p.y() < 5.0 && b.depth > 0.5;
  });
  const auto [south_point, south_wall] = labelledBlock(map, [](const Eigen::Vector3d& p, const Block& b) {
    return b.isVertical() && p.y() < 0.05 && p.x() > 1.0 && p.x() < 7.0 && b.depth > 0.5;
  });
  CHECK(floor != east_wall);
  CHECK(east_wall != south_wall);
  const auto floor_colour = voxelColour(*coloured, floor_point, Eigen::Vector3d::UnitZ());
  const auto east_colour = voxelColour(*coloured, {8.0, east_point.y(), east_point.z()}, Eigen::Vector3d::UnitX());
  const auto south_colour = voxelColour(*coloured, {south_point.x(), 0.0, south_point.z()}, Eigen::Vector3d::UnitY());
  REQUIRE(floor_colour);
  REQUIRE(east_colour);
  REQUIRE(south_colour);
  CHECK(*floor_colour == io::planeColour(floor));
  CHECK(*east_colour == io::planeColour(east_wall));
  CHECK(*south_colour == io::planeColour(south_wall));
  CHECK_FALSE(*floor_colour == io::kUnlabelledColour);

  // Every occupied voxel of the map is there, and nothing else.
  std::size_t occupied = 0;
  for (auto leaf = map.octree().begin_leafs(); leaf != map.octree().end_leafs(); ++leaf) {
    if (map.octree().isNodeOccupied(*leaf)) ++occupied;
  }
  std::size_t exported = 0;
  for (auto leaf = coloured->begin_leafs(); leaf != coloured->end_leafs(); ++leaf) {
    CHECK(coloured->isNodeOccupied(*leaf));
    ++exported;
  }
  CHECK(exported == occupied);
}

TEST_CASE("Export: the dashboard's voxels are the ColorOcTree's, each with the plane of its colour") {
  const Map map = labelledRooms(true);
  const std::unique_ptr<octomap::ColorOcTree> coloured = io::colouredOctree(map);
  const std::string bytes = io::dashboardVoxels(map);
  const io::DashboardVoxels read = io::parseDashboardVoxels(bytes, "voxels.bin");
  CHECK(read.voxel_size == doctest::Approx(coloured->getResolution()));
  CHECK(bytes.size() == 24 + 16 * read.voxels.size());
  CHECK(read.voxels.size() == coloured->getNumLeafNodes());
  std::set<std::tuple<int, int, int>> seen;
  std::size_t labelled = 0;
  for (const io::DashboardVoxel& voxel : read.voxels) {
    const Eigen::Vector3d centre =
        (Eigen::Vector3d(voxel.index[0], voxel.index[1], voxel.index[2]) + Eigen::Vector3d::Constant(0.5)) * read.voxel_size;
    const octomap::ColorOcTreeNode* node = coloured->search(centre.x(), centre.y(), centre.z());
    REQUIRE(node != nullptr);
    CHECK(coloured->isNodeOccupied(node));
    const auto colour = node->getColor();
    CHECK(io::Rgb{colour.r, colour.g, colour.b} == io::planeColour(voxel.plane));
    CHECK(seen.emplace(voxel.index[0], voxel.index[1], voxel.index[2]).second);
    labelled += voxel.plane != 0 ? 1 : 0;
  }
  CHECK(labelled > read.voxels.size() / 2);
  // Damaged files are refused, naming the file.
  CHECK_THROWS_WITH(io::parseDashboardVoxels(bytes.substr(0, bytes.size() - 2), "v.bin"),
                    doctest::Contains("v.bin: the header says"));
  CHECK_THROWS_WITH(io::parseDashboardVoxels("MLBLOCKS", "v.bin"), "v.bin: not an mlmap voxels file (no \"MLVOXELS\" header)");
  std::string version_two = bytes;
  version_two[8] = 2;
  CHECK_THROWS_WITH(io::parseDashboardVoxels(version_two, "v.bin"), "v.bin: voxels file version 2, this reader knows version 1");
  std::string no_size = bytes;
  std::fill(no_size.begin() + 16, no_size.begin() + 24, '\0');
  CHECK_THROWS_WITH(io::parseDashboardVoxels(no_size, "v.bin"), "v.bin: the voxel size is not a positive number");
}

TEST_CASE("Export: the palette is stable, grey for no plane, and neighbouring ids differ") {
  CHECK(io::planeColour(0) == io::kUnlabelledColour);
  CHECK(io::planeColour(7) == io::planeColour(7));
  std::set<std::tuple<int, int, int>> colours;
  for (std::int32_t id = 1; id <= 40; ++id) {
    const io::Rgb colour = io::planeColour(id);
    colours.emplace(colour.red, colour.green, colour.blue);
    const io::Rgb next = io::planeColour(id + 1);
    const int difference = std::abs(colour.red - next.red) + std::abs(colour.green - next.green) +
                           std::abs(colour.blue - next.blue);
    CHECK(difference > 60);
  }
  CHECK(colours.size() == 40);
}

TEST_CASE("Export: blocks PLY and .bt read back, a failed export leaves the old file alone") {
  const test::TempDir dir;
  const Map map = labelledRooms(true);
  io::writeBlocksPly(dir / "blocks.ply", map);
  const Scan blocks = io::readPly(dir / "blocks.ply");
  REQUIRE(blocks.size() == map.blocks().blockCount());
  REQUIRE(blocks.labels.size() == blocks.size());
  std::size_t labelled = 0;
  for (const auto label : blocks.labels) labelled += label > 0 ? 1 : 0;
  CHECK(labelled == map.blocks().stats().labelled_blocks);

  io::writeBinaryOctree(dir / "map.bt", map);
  octomap::OcTree tree(0.1);
  REQUIRE(tree.readBinary((dir / "map.bt").string()));
  CHECK(tree.getResolution() == doctest::Approx(0.05));
  // Maximum likelihood and pruned, byte for byte what OctoMap's own writeBinary writes
  // (which converts and prunes the tree in place, hence on a copy); the map keeps its log-odds.
  octomap::OcTree copy(map.octree());
  std::ostringstream octomap_bt;
  REQUIRE(copy.writeBinary(octomap_bt));
  CHECK(test::readText(dir / "map.bt") == octomap_bt.str());
  CHECK(tree.size() < map.octree().size());
  CHECK(tree.size() == copy.size());

  Map no_octree(MapConfig{0.05, 0.0, -1.0, false});
  const std::string old_bytes = test::readText(dir / "map.bt");
  CHECK_THROWS_AS(io::writeBinaryOctree(dir / "map.bt", no_octree), Error);
  CHECK(test::readText(dir / "map.bt") == old_bytes);
  // A map without an OcTree still gets a ColorOcTree, from its blocks.
  Map blocks_only = labelledRooms(false);
  const auto from_blocks = io::colouredOctree(blocks_only);
  CHECK(from_blocks->size() > 1000);
}
