// .mlmap files: write, read back, compare; and every kind of damage is refused.
#include <doctest/doctest.h>

#include <cstring>
#include <random>

#include "../src/io/crc32.hpp"
#include "helpers.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/map_file.hpp"
#include "mlmap/io/planes_json.hpp"

using namespace mlmap;

namespace {

// A version-3 file's bytes in an older version's layout: each block without its 40
// bytes of point moments, the version byte set, the checksum made anew.
// A version-4 file's bytes in an older layout: without the origin (version 3 and before),
// and without the blocks' point moments (versions 1-2).
std::string olderLayout(const std::string& v4, char version) {
  constexpr std::size_t kHeader = 8 + 4 + 4 + 3 * 8;
  constexpr std::size_t kOrigin = 3 * 8;
  std::uint64_t cells = 0;
  std::memcpy(&cells, v4.data() + kHeader + kOrigin, sizeof(cells));
  std::string out = v4.substr(0, kHeader) + v4.substr(kHeader + kOrigin, 16);
  out[8] = version;
  std::size_t at = kHeader + kOrigin + 16;
  const std::size_t kept = version >= 3 ? 57 : 17;
  for (std::uint64_t c = 0; c < cells; ++c) {
    std::uint16_t count = 0;
    std::memcpy(&count, v4.data() + at + 8, sizeof(count));
    out.append(v4, at, 10);
    at += 10;
    for (std::uint16_t k = 0; k < count; ++k, at += 57) out.append(v4, at, kept);
  }
  out.append(v4, at, v4.size() - 4 - at);
  const std::uint32_t crc = io::crc32(out.data(), out.size());
  out.append(reinterpret_cast<const char*>(&crc), sizeof(crc));
  return out;
}

Map smallRoomMap(bool with_octree) {
  MapConfig config;
  config.cell_size = 0.1;
  config.with_octree = with_octree;
  Map map(config);
  Scan scan;
  scan.pose.translation() = Eigen::Vector3d(1.0, 1.0, 0.5);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(-0.9, 0.9);
  for (int k = 0; k < 3000; ++k) {
    scan.points.emplace_back(coordinate(random), coordinate(random), -0.5);   // floor
    scan.points.emplace_back(coordinate(random), coordinate(random), 1.5);    // ceiling
    scan.points.emplace_back(0.95, coordinate(random), coordinate(random) + 0.5);  // wall
  }
  map.insertScan(scan);
  map.compact();
  map.blocks().mutableBlocksAt(0)[0].plane = 7;
  return map;
}

void checkSameBlocks(const MLMap& a, const MLMap& b) {
  REQUIRE(a.blockCount() == b.blockCount());
  REQUIRE(a.cellCount() == b.cellCount());
  for (std::size_t n = 0; n < a.cellCount(); ++n) {
    const auto expected = a.blocksAt(n);
    const auto actual = b.blocks(a.cellAt(n));
    REQUIRE(actual.size() == expected.size());
    for (std::size_t k = 0; k < expected.size(); ++k) {
      CHECK(actual[k].height == expected[k].height);
      CHECK(actual[k].variance == expected[k].variance);
      CHECK(actual[k].depth == expected[k].depth);
      CHECK(actual[k].plane == expected[k].plane);
      CHECK(actual[k].kind == expected[k].kind);
    }
  }
}

}  // namespace

TEST_CASE("MapFile: a map with its OcTree round-trips exactly") {
  test::TempDir dir;
  const Map map = smallRoomMap(true);
  io::writeMap(dir / "room.mlmap", map);
  const Map read = io::readMap(dir / "room.mlmap");
  CHECK(read.config().cell_size == map.config().cell_size);
  checkSameBlocks(map.blocks(), read.blocks());
  REQUIRE(read.hasOctree());
  CHECK(read.octree().size() == map.octree().size());
  CHECK(read.octree().getResolution() == map.octree().getResolution());
  // The same voxels with the same log-odds.
  std::size_t compared = 0;
  for (auto it = map.octree().begin_leafs(); it != map.octree().end_leafs(); ++it, ++compared) {
    const auto* node = read.octree().search(it.getKey(), static_cast<unsigned>(it.getDepth()));
    REQUIRE(node != nullptr);
    CHECK(node->getLogOdds() == it->getLogOdds());
  }
  CHECK(compared > 100);
  // Only the map is left in the directory: no temporary file.
  CHECK(std::distance(std::filesystem::directory_iterator(dir.path()),
                      std::filesystem::directory_iterator()) == 1);
}

TEST_CASE("MapFile: a block-only map round-trips") {
  test::TempDir dir;
  const Map map = smallRoomMap(false);
  io::writeMap(dir / "blocks.mlmap", map);
  const Map read = io::readMap(dir / "blocks.mlmap");
  CHECK_FALSE(read.hasOctree());
  checkSameBlocks(map.blocks(), read.blocks());
}

TEST_CASE("MapFile: damaged, truncated, foreign and future files are refused by name") {
  test::TempDir dir;
  io::writeMap(dir / "good.mlmap", smallRoomMap(true));
  const std::string good = test::readText(dir / "good.mlmap");

  SUBCASE("missing") {
    CHECK_THROWS_WITH_AS(io::readMap(dir / "none.mlmap"), doctest::Contains("none.mlmap"), Error);
  }
  SUBCASE("not a map") {
    test::writeText(dir / "text.mlmap", "x y z\n1 2 3\n");
    CHECK_THROWS_WITH_AS(io::readMap(dir / "text.mlmap"), doctest::Contains("bad magic"), Error);
  }
  SUBCASE("a flipped byte") {
    std::string damaged = good;
    damaged[damaged.size() / 2] ^= 0x10;
    test::writeText(dir / "flip.mlmap", damaged);
    CHECK_THROWS_WITH_AS(io::readMap(dir / "flip.mlmap"), doctest::Contains("checksum"), Error);
  }
  SUBCASE("truncated") {
    test::writeText(dir / "cut.mlmap", good.substr(0, good.size() / 3));
    CHECK_THROWS_WITH_AS(io::readMap(dir / "cut.mlmap"), doctest::Contains("cut.mlmap"), Error);
    test::writeText(dir / "tiny.mlmap", good.substr(0, 10));
    CHECK_THROWS_AS(io::readMap(dir / "tiny.mlmap"), Error);
  }
  SUBCASE("another version") {
    std::string future = good;
    future[8] = static_cast<char>(io::kMapFileVersion + 1);
    test::writeText(dir / "future.mlmap", future);
    const std::string expected = "version " + std::to_string(io::kMapFileVersion + 1);
    CHECK_THROWS_WITH_AS(io::readMap(dir / "future.mlmap"), doctest::Contains(expected.c_str()), Error);
  }
  SUBCASE("a hostile cell count with a valid checksum") {
    std::string hostile = good.substr(0, good.size() - 4);
    const std::uint64_t huge = 1ULL << 60;
    std::memcpy(hostile.data() + 64, &huge, sizeof(huge));
    const std::uint32_t crc = io::crc32(hostile.data(), hostile.size());
    hostile.append(reinterpret_cast<const char*>(&crc), sizeof(crc));
    test::writeText(dir / "hostile.mlmap", hostile);
    CHECK_THROWS_WITH_AS(io::readMap(dir / "hostile.mlmap"), doctest::Contains("more than the file"),
                         Error);
  }
}

TEST_CASE("MapFile: a failed write leaves the old file untouched") {
  test::TempDir dir;
  io::writeMap(dir / "map.mlmap", smallRoomMap(false));
  const std::string before = test::readText(dir / "map.mlmap");
  CHECK_THROWS_AS(io::writeMap(dir / "no-such-dir" / "map.mlmap", smallRoomMap(false)), Error);
  CHECK(test::readText(dir / "map.mlmap") == before);
}

TEST_CASE("MapFile: a labelled map keeps its planes, and version-1 files still read") {
  const test::TempDir dir;
  Map map = smallRoomMap(false);
  PlaneDetection detection;
  Plane plane;
  plane.id = 7;
  plane.label = PlaneClass::Floor;
  plane.offset = 0.0;
  plane.area = 2.5;
  plane.block_count = 1;
  plane.source = 1;
  plane.outline = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}};
  detection.planes.push_back(plane);
  detection.stats.candidates = 42;
  detection.config.seed = 9;
  map.setPlanes(detection);
  io::writeMap(dir / "labelled.mlmap", map);
  const Map back = io::readMap(dir / "labelled.mlmap");
  REQUIRE(back.planes().has_value());
  REQUIRE(back.planes()->planes.size() == 1);
  const Plane& read = back.planes()->planes[0];
  CHECK(read.id == 7);
  CHECK(read.label == PlaneClass::Floor);
  CHECK(read.area == doctest::Approx(2.5));
  CHECK(read.outline.size() == 3);
  CHECK(back.planes()->stats.candidates == 42);
  CHECK(back.planes()->config.seed == 9);
  CHECK(back.blocks().blocksAt(0)[0].plane == 7);

  // A version-1 file is the version-2 layout without planes, and version 2 the
  // version-3 layout without the blocks' point moments: an unlabelled map's bytes
  // rewritten so, its checksum fixed.
  Map unlabelled = smallRoomMap(false);
  io::writeMap(dir / "v3.mlmap", unlabelled);
  const std::string bytes = olderLayout(test::readText(dir / "v3.mlmap"), 1);
  test::writeText(dir / "v1.mlmap", bytes);
  const Map v2 = [&] {
    test::writeText(dir / "v2.mlmap", olderLayout(test::readText(dir / "v3.mlmap"), 2));
    return io::readMap(dir / "v2.mlmap");
  }();
  CHECK(v2.blocks().blockCount() == unlabelled.blocks().blockCount());
  CHECK(v2.blocks().blocksAt(0)[0].points.empty());
  CHECK_FALSE(unlabelled.blocks().blocksAt(0)[0].points.empty());
  const Map old = io::readMap(dir / "v1.mlmap");
  CHECK_FALSE(old.planes().has_value());
  CHECK(old.blocks().blockCount() == unlabelled.blocks().blockCount());
  // Version 3: the version-4 layout without the map's origin (the world's).
  test::writeText(dir / "v3-layout.mlmap", olderLayout(test::readText(dir / "v3.mlmap"), 3));
  const Map v3 = io::readMap(dir / "v3-layout.mlmap");
  CHECK(v3.blocks().blockCount() == unlabelled.blocks().blockCount());
  CHECK_FALSE(v3.blocks().blocksAt(0)[0].points.empty());
  CHECK(v3.config().origin.isZero());

  // New scans invalidate the labels.
  Map changed = io::readMap(dir / "labelled.mlmap");
  Scan scan;
  scan.points.emplace_back(0.5, 0.5, 0.0);
  changed.insertScan(scan);
  CHECK_FALSE(changed.planes().has_value());
  CHECK(changed.blocks().stats().labelled_blocks == 0);
}

// The origin of a map far from the world's (a national grid's coordinates) is kept, and its
// planes, stored in the world's coordinates, come back in the map's frame.
TEST_CASE("MapFile: a map's origin is kept and its planes come back in its frame") {
  const test::TempDir dir;
  Map map = smallRoomMap(false);
  Map far(map.config());
  const Eigen::Vector3d origin(500000.0, 5000000.0, 300.0);
  far.setOrigin(origin);
  Scan scan;
  scan.points = {Point(0.5, 0.5, 0.0), Point(0.6, 0.5, 0.0)};
  far.insertScan(scan);
  CHECK_THROWS_AS(far.setOrigin(Eigen::Vector3d::Zero()), Error);  // not once it holds a scan
  PlaneDetection detection;
  Plane plane;
  plane.id = 1;
  plane.normal = Eigen::Vector3d::UnitZ();
  plane.offset = -0.25;  // z = 0.25 in the map's frame
  plane.area = 1.0;
  plane.block_count = 2;
  plane.source = 1;
  plane.centroid = Eigen::Vector3d(0.5, 0.5, 0.25);
  plane.outline = {{0, 0, 0.25}, {1, 0, 0.25}, {1, 1, 0.25}};
  detection.planes.push_back(plane);
  far.setPlanes(detection);
  io::writeMap(dir / "far.mlmap", far);
  const Map back = io::readMap(dir / "far.mlmap");
  CHECK(back.config().origin.isApprox(origin));
  REQUIRE(back.planes().has_value());
  const Plane& read = back.planes()->planes[0];
  CHECK(read.offset == doctest::Approx(-0.25).epsilon(1e-9));
  CHECK(read.centroid.isApprox(Eigen::Vector3d(0.5, 0.5, 0.25), 1e-9));
  CHECK(read.outline[1].isApprox(Eigen::Vector3d(1, 0, 0.25), 1e-9));
  // The planes JSON speaks the world's coordinates.
  const std::string json = io::planesJson(back, *back.planes(), "far.mlmap");
  CHECK(json.find("\"centroid\":[500000.5,5000000.5,300.25]") != std::string::npos);
  CHECK(json.find("\"origin\":[500000.0,5000000.0,300.0]") != std::string::npos);
}

TEST_CASE("MapFile: CRC-32 is zlib's (IEEE 802.3), also taken in pieces") {
  const std::string check = "123456789";
  CHECK(io::crc32(check.data(), check.size()) == 0xCBF43926U);
  CHECK(io::crc32(check.data() + 4, 5, io::crc32(check.data(), 4)) == 0xCBF43926U);
  CHECK(io::crc32(nullptr, 0) == 0U);
}

TEST_CASE("MapFile: the summary counts the OcTree section as the built tree reports it") {
  test::TempDir dir;
  const Map map = smallRoomMap(true);
  io::writeMap(dir / "room.mlmap", map);
  const io::MapSummary summary = io::readMapSummary(dir / "room.mlmap");
  CHECK_FALSE(summary.map.hasOctree());
  CHECK(summary.map.blocks().blockCount() == 0);  // counted, not restored
  REQUIRE(summary.octree.has_value());
  const octomap::OcTree& tree = map.octree();
  std::size_t occupied = 0;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) occupied += tree.isNodeOccupied(*it) ? 1 : 0;
  CHECK(summary.octree->resolution == tree.getResolution());
  CHECK(summary.octree->nodes == tree.size());
  CHECK(summary.octree->leaves == tree.getNumLeafNodes());
  CHECK(summary.octree->occupied_leaves == occupied);
  CHECK(summary.octree->memory_bytes == tree.memoryUsage());
  io::writeMap(dir / "blocks.mlmap", smallRoomMap(false));
  CHECK_FALSE(io::readMapSummary(dir / "blocks.mlmap").octree.has_value());
}

TEST_CASE("MapFile: the summary counts the blocks as the restored map's stats() reports them") {
  test::TempDir dir;
  Map map = smallRoomMap(false);
  map.blocks().mutableBlocksAt(0)[0].plane = 3;  // one labelled block
  io::writeMap(dir / "room.mlmap", map);
  const MLMapStats restored = io::readMap(dir / "room.mlmap").blocks().stats();
  const MLMapStats counted = io::readMapSummary(dir / "room.mlmap").blocks;
  REQUIRE(restored.blocks > 100);
  CHECK(counted.cells == restored.cells);
  CHECK(counted.blocks == restored.blocks);
  CHECK(counted.horizontal_blocks == restored.horizontal_blocks);
  CHECK(counted.vertical_blocks == restored.vertical_blocks);
  CHECK(counted.labelled_blocks == restored.labelled_blocks);
  CHECK(counted.labelled_blocks == 1);
  CHECK(counted.memory_bytes == restored.memory_bytes);
  CHECK(counted.min == restored.min);
  CHECK(counted.max == restored.max);
  CHECK(restored.vertical_blocks > 0);
}

TEST_CASE("MapFile: the summary refuses a damaged OcTree section that the checksum covers") {
  test::TempDir dir;
  const Map map = smallRoomMap(true);
  io::writeMap(dir / "room.mlmap", map);
  const std::string good = test::readText(dir / "room.mlmap");
  const std::size_t data_line = good.find("data\n");
  REQUIRE(data_line != std::string::npos);
  const auto resealed = [](std::string body) {
    const std::uint32_t crc = io::crc32(body.data(), body.size());
    body.append(reinterpret_cast<const char*>(&crc), sizeof(crc));
    return body;
  };
  SUBCASE("a node claims children the stream does not hold") {
    std::string damaged = good.substr(0, good.size() - 4);
    damaged[data_line + 5 + 4] = static_cast<char>(0xFF);  // the root's child bits
    test::writeText(dir / "damaged.mlmap", resealed(damaged));
    CHECK_THROWS_WITH_AS(io::readMapSummary(dir / "damaged.mlmap"), doctest::Contains("OcTree byte"), Error);
  }
  SUBCASE("a header that is not an OcTree's") {
    std::string damaged = good.substr(0, good.size() - 4);
    damaged.replace(damaged.find("id OcTree"), 9, "id OcTreX");
    test::writeText(dir / "damaged.mlmap", resealed(damaged));
    CHECK_THROWS_WITH_AS(io::readMapSummary(dir / "damaged.mlmap"), doctest::Contains("not OcTree"), Error);
  }
}
