// LevelCover: where each level patch's blocks lie within a reach of cells (the point
// labels' search for a floor at a far box side's foot).
#include <doctest/doctest.h>

#include <set>
#include <vector>

#include "../src/planes/level_cover.hpp"
#include "mlmap/map/ml_map.hpp"

using namespace mlmap;

namespace {

Block levelBlock(std::int32_t plane, float height) {
  Block block;
  block.height = height;
  block.variance = 1e-4F;
  block.plane = plane;
  return block;
}

std::set<std::uint32_t> near(const LevelCover& cover, CellIndex cell) {
  std::set<std::uint32_t> slots;
  cover.forEachNear(cell, [&](std::uint32_t slot) { slots.insert(slot); });
  return slots;
}

}  // namespace

TEST_CASE("Level cover: a level patch's blocks cover the square of the reach round them, and only level patches count") {
  MLMap map(0.05);
  // Patch 7 (slot 1, level): two blocks 10 cells apart along a row; patch 9 (slot 2, not
  // level): a block beside them; a block of no patch.
  map.restoreCell(CellIndex{0, 0}, std::vector<Block>{levelBlock(7, 0.0F)});
  map.restoreCell(CellIndex{0, 10}, std::vector<Block>{levelBlock(7, 0.0F)});
  map.restoreCell(CellIndex{5, 5}, std::vector<Block>{levelBlock(9, 0.5F)});
  map.restoreCell(CellIndex{-20, -20}, std::vector<Block>{levelBlock(0, 0.0F)});
  const auto slot_of = [](std::int32_t id) -> std::uint32_t { return id == 7 ? 1 : id == 9 ? 2 : 0; };
  const LevelCover cover(map, slot_of, {false, true, false}, 3);

  CHECK(near(cover, CellIndex{0, 0}) == std::set<std::uint32_t>{1});
  CHECK(near(cover, CellIndex{3, 3}) == std::set<std::uint32_t>{1});    // the square's corner
  CHECK(near(cover, CellIndex{-3, 13}) == std::set<std::uint32_t>{1});  // the other block's
  CHECK(near(cover, CellIndex{0, 7}) == std::set<std::uint32_t>{1});
  CHECK(near(cover, CellIndex{0, 5}).empty());   // between them, 5 cells from each
  CHECK(near(cover, CellIndex{4, 0}).empty());   // one past the reach
  CHECK(near(cover, CellIndex{0, -4}).empty());
  CHECK(near(cover, CellIndex{5, 5}).empty());   // patch 9's own cell: not level
  CHECK(near(cover, CellIndex{-20, -20}).empty());
  CHECK(near(cover, CellIndex{1000, -1000}).empty());
}
