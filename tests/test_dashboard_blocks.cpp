// The dashboard's blocks file (mlmap.blocks/1): written from a map, read back block by
// block; damaged files refused with a message; the base64 of blocks.js.
#include <doctest/doctest.h>

#include <cstring>
#include <limits>

#include "mlmap/error.hpp"
#include "mlmap/io/dashboard.hpp"
#include "mlmap/io/dashboard_blocks.hpp"

using namespace mlmap;

namespace {

// Two cells, one at negative indices, with a floor, a wall and a labelled table.
MLMap smallMap() {
  MLMap map(0.05);
  const Block floor{0.01F, 1e-4F, 0.0F, 3, BlockKind::Horizontal, {}};
  const Block wall{2.4F, 2e-4F, 2.0F, 7, BlockKind::Vertical, {}};
  const Block table{0.75F, 1e-4F, 0.0F, 0, BlockKind::Horizontal, {}};
  const Block cells_a[] = {floor, wall};
  const Block cells_b[] = {floor, table};
  map.restoreCell({-4, 12}, cells_a);
  map.restoreCell({9, -2}, cells_b);
  return map;
}

std::string withByte(std::string bytes, std::size_t at, char value) {
  bytes.at(at) = value;
  return bytes;
}

}  // namespace

TEST_CASE("Dashboard blocks: every block read back with its cell, top, depth, plane and kind") {
  const MLMap map = smallMap();
  const std::string bytes = io::dashboardBlocks(map);
  CHECK(bytes.size() == 24 + 21 * 4);
  CHECK(bytes.substr(0, 8) == "MLBLOCKS");
  const io::DashboardBlocks read = io::parseDashboardBlocks(bytes, "blocks.bin");
  CHECK(read.cell_size == 0.05);
  REQUIRE(read.blocks.size() == map.blockCount());
  std::size_t k = 0;
  for (std::size_t n = 0; n < map.cellCount(); ++n) {
    for (const Block& block : map.blocksAt(n)) {
      const io::DashboardBlock& got = read.blocks[k++];
      CHECK(got.cell == map.cellAt(n));
      CHECK(got.top == block.height);
      CHECK(got.depth == block.depth);
      CHECK(got.plane == block.plane);
      CHECK(got.kind == block.kind);
    }
  }
  // The layout the page relies on: column j first, little-endian.
  std::int32_t first_j = 0;
  std::memcpy(&first_j, bytes.data() + 24, 4);
  CHECK(first_j == 12);
  CHECK(io::parseDashboardBlocks(io::dashboardBlocks(MLMap(0.1)), "empty").blocks.empty());
}

TEST_CASE("Dashboard blocks: a damaged file is refused with a message naming it") {
  const std::string bytes = io::dashboardBlocks(smallMap());
  const auto message = [](const std::string& damaged) {
    try {
      io::parseDashboardBlocks(damaged, "b.bin");
    } catch (const Error& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  CHECK(message("") == "b.bin: not an mlmap blocks file (no \"MLBLOCKS\" header)");
  CHECK(message(withByte(bytes, 0, 'X')).find("not an mlmap blocks file") != std::string::npos);
  CHECK(message(withByte(bytes, 8, 2)) == "b.bin: blocks file version 2, this reader knows version 1");
  CHECK(message(bytes.substr(0, bytes.size() - 1)).find("the header says 4 blocks, which take 108 bytes, but the file has 107") !=
        std::string::npos);
  CHECK(message(bytes + "x").find("but the file has 109") != std::string::npos);
  // A count near 2^32 must not overflow the size check.
  CHECK(message(withByte(withByte(bytes, 12, '\xff'), 15, '\xff')).find("cut short or damaged") != std::string::npos);
  std::string zero_cell = bytes;
  std::memset(zero_cell.data() + 16, 0, 8);
  CHECK(message(zero_cell) == "b.bin: the cell size is not a positive number");
  std::string nan_top = bytes;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan_top.data() + 24 + 8 * 4 + 4, &nan, 4);
  CHECK(message(nan_top) == "b.bin: block 1: the top is not a finite number");
  std::string negative_depth = bytes;
  const float minus_one = -1.0F;
  std::memcpy(negative_depth.data() + 24 + 12 * 4, &minus_one, 4);
  CHECK(message(negative_depth) == "b.bin: block 0: the depth is not a number ≥ 0");
  CHECK(message(withByte(bytes, 24 + 20 * 4 + 3, 5)) == "b.bin: block 3: kind 5, expected 0 (horizontal) or 1 (vertical)");
  CHECK(message(bytes) == "accepted");
}

TEST_CASE("Dashboard blocks: base64 as RFC 4648 gives it") {
  CHECK(io::base64("") == "");
  CHECK(io::base64("f") == "Zg==");
  CHECK(io::base64("fo") == "Zm8=");
  CHECK(io::base64("foo") == "Zm9v");
  CHECK(io::base64("foob") == "Zm9vYg==");
  CHECK(io::base64("fooba") == "Zm9vYmE=");
  CHECK(io::base64("foobar") == "Zm9vYmFy");
  CHECK(io::base64(std::string("\xff\xfe\x00", 3)) == "//4A");
}
