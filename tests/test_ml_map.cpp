// The ML map's update rules, one test per case of Fig. 3, and its invariants.
#include <doctest/doctest.h>

#include <algorithm>
#include <random>

#include "mlmap/error.hpp"
#include "mlmap/map/ml_map.hpp"

using mlmap::Block;
using mlmap::BlockKind;
using mlmap::CellIndex;
using mlmap::MLMap;
using mlmap::Point;

namespace {

constexpr double kCell = 0.1;
constexpr double kVar = 1e-4;  // (1 cm)²

std::vector<Block> blocksAt(const MLMap& map, double x, double y) {
  const auto span = map.blocks(map.cellOf(x, y));
  return {span.begin(), span.end()};
}

// Blocks in a cell are sorted and separated by at least one cell_size.
void checkCellInvariants(const MLMap& map) {
  std::size_t total = 0;
  for (std::size_t n = 0; n < map.cellCount(); ++n) {
    const auto blocks = map.blocksAt(n);
    total += blocks.size();
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      REQUIRE(blocks[k].depth >= 0.0F);
      if (!blocks[k].isVertical()) REQUIRE(blocks[k].depth == 0.0F);
      if (k > 0) REQUIRE(blocks[k].bottom() - blocks[k - 1].height >= kCell - 1e-6);
    }
  }
  REQUIRE(total == map.blockCount());
}

}  // namespace

TEST_CASE("MLMap: cell (i, j) is (floor(y / cell), floor(x / cell))") {
  MLMap map(kCell);
  CHECK(map.cellOf(0.15, -0.05) == CellIndex{-1, 1});
  CHECK(map.cellOf(0.0, 0.0) == CellIndex{0, 0});
  CHECK(map.cellOf(-0.0001, 0.25) == CellIndex{2, -1});
  const auto centre = map.cellCenter(CellIndex{-1, 1});
  CHECK(centre.x() == doctest::Approx(0.15));
  CHECK(centre.y() == doctest::Approx(-0.05));
  CHECK_THROWS_AS(map.cellOf(1e300, 0.0), mlmap::Error);
  CHECK_THROWS_AS(MLMap(0.0), mlmap::Error);
}

TEST_CASE("MLMap Fig. 3 case 1: a point far from every block makes a new horizontal block") {
  MLMap map(kCell);
  map.insert(Point(0.05, 0.05, 0.0), kVar);
  auto blocks = blocksAt(map, 0.05, 0.05);
  REQUIRE(blocks.size() == 1);
  CHECK(blocks[0].kind == BlockKind::Horizontal);
  CHECK(blocks[0].height == doctest::Approx(0.0));
  CHECK(blocks[0].variance == doctest::Approx(kVar));
  CHECK(blocks[0].depth == 0.0F);
  // One cell_size above the block is not collected: a second block, kept in order.
  map.insert(Point(0.05, 0.05, 0.75), kVar);
  map.insert(Point(0.05, 0.05, 0.3), kVar);
  blocks = blocksAt(map, 0.05, 0.05);
  REQUIRE(blocks.size() == 3);
  CHECK(blocks[0].height == doctest::Approx(0.0));
  CHECK(blocks[1].height == doctest::Approx(0.3));
  CHECK(blocks[2].height == doctest::Approx(0.75));
  // Another cell is another list.
  map.insert(Point(0.15, 0.05, 0.0), kVar);
  CHECK(map.cellCount() == 2);
  CHECK(map.blockCount() == 4);
}

TEST_CASE("MLMap Fig. 3 case 5: a horizontal block is Kalman-updated, or turns vertical past 3 sigma") {
  MLMap map(kCell);
  SUBCASE("close: Kalman update, stays horizontal") {
    map.insert(Point(0.05, 0.05, 0.0), kVar);
    map.insert(Point(0.05, 0.05, 0.01), kVar);
    const auto blocks = blocksAt(map, 0.05, 0.05);
    REQUIRE(blocks.size() == 1);
    CHECK(blocks[0].kind == BlockKind::Horizontal);
    CHECK(blocks[0].height == doctest::Approx(0.005));
    CHECK(blocks[0].variance == doctest::Approx(kVar / 2));
    // Unequal variances weigh towards the surer measurement.
    map.insert(Point(0.05, 0.05, 0.0), 4 * kVar);
    const auto after = blocksAt(map, 0.05, 0.05);
    CHECK(after[0].height == doctest::Approx((4 * kVar * 0.005 + kVar / 2 * 0.0) / (4.5 * kVar)));
  }
  SUBCASE("above 3 sigma: vertical, h = max, d = |p_z - h|, sigma of the top measurement") {
    map.insert(Point(0.05, 0.05, 0.0), kVar);
    map.insert(Point(0.05, 0.05, 0.06), 2 * kVar);  // gate 3·sqrt(3e-4) = 0.052
    const auto blocks = blocksAt(map, 0.05, 0.05);
    REQUIRE(blocks.size() == 1);
    CHECK(blocks[0].kind == BlockKind::Vertical);
    CHECK(blocks[0].height == doctest::Approx(0.06));
    CHECK(blocks[0].depth == doctest::Approx(0.06));
    CHECK(blocks[0].variance == doctest::Approx(2 * kVar));
  }
  SUBCASE("below 3 sigma: vertical, h kept, depth down to the point") {
    map.insert(Point(0.05, 0.05, 0.0), kVar);
    map.insert(Point(0.05, 0.05, -0.06), 2 * kVar);
    const auto blocks = blocksAt(map, 0.05, 0.05);
    REQUIRE(blocks.size() == 1);
    CHECK(blocks[0].kind == BlockKind::Vertical);
    CHECK(blocks[0].height == doctest::Approx(0.0));
    CHECK(blocks[0].depth == doctest::Approx(0.06));
    CHECK(blocks[0].variance == doctest::Approx(kVar));
  }
}

TEST_CASE("MLMap Fig. 3 case 2: a point near the top or bottom of a vertical block extends it") {
  MLMap map(kCell);
  map.insert(Point(0.05, 0.05, 0.5), kVar);
  map.insert(Point(0.05, 0.05, 0.58), kVar);  // vertical [0.5, 0.58]
  map.insert(Point(0.05, 0.05, 0.66), 3 * kVar);  // within a cell of the top
  auto blocks = blocksAt(map, 0.05, 0.05);
  REQUIRE(blocks.size() == 1);
  CHECK(blocks[0].isVertical());
  CHECK(blocks[0].height == doctest::Approx(0.66));
  CHECK(blocks[0].bottom() == doctest::Approx(0.5));
  CHECK(blocks[0].variance == doctest::Approx(3 * kVar));
  map.insert(Point(0.05, 0.05, 0.41), kVar);  // within a cell of the bottom
  blocks = blocksAt(map, 0.05, 0.05);
  REQUIRE(blocks.size() == 1);
  CHECK(blocks[0].height == doctest::Approx(0.66));
  CHECK(blocks[0].bottom() == doctest::Approx(0.41));
  CHECK(blocks[0].variance == doctest::Approx(3 * kVar));  // the top's, unchanged
}

TEST_CASE("MLMap Fig. 3 case 3: a point inside a vertical block changes nothing") {
  MLMap map(kCell);
  for (double z = 0.0; z <= 1.0; z += 0.05) map.insert(Point(0.05, 0.05, z), kVar);
  const auto before = blocksAt(map, 0.05, 0.05);
  REQUIRE(before.size() == 1);
  REQUIRE(before[0].isVertical());
  map.insert(Point(0.05, 0.05, 0.5), 9 * kVar);
  const auto after = blocksAt(map, 0.05, 0.05);
  REQUIRE(after.size() == 1);
  CHECK(after[0].height == before[0].height);
  CHECK(after[0].depth == before[0].depth);
  CHECK(after[0].variance == before[0].variance);
}

TEST_CASE("MLMap Fig. 3 case 4: a point collected by two blocks merges them into one vertical block") {
  MLMap map(kCell);
  map.insert(Point(0.05, 0.05, 0.0), kVar);
  map.insert(Point(0.05, 0.05, 0.15), 2 * kVar);
  map.insert(Point(0.05, 0.05, 2.0), kVar);  // a ceiling, out of reach
  REQUIRE(blocksAt(map, 0.05, 0.05).size() == 3);
  map.insert(Point(0.05, 0.05, 0.075), kVar);  // within a cell of both
  const auto blocks = blocksAt(map, 0.05, 0.05);
  REQUIRE(blocks.size() == 2);
  CHECK(blocks[0].isVertical());
  CHECK(blocks[0].height == doctest::Approx(0.15));
  CHECK(blocks[0].bottom() == doctest::Approx(0.0));
  CHECK(blocks[0].variance == doctest::Approx(2 * kVar));
  CHECK(blocks[1].height == doctest::Approx(2.0));
  CHECK(map.blockCount() == 2);
}

TEST_CASE("MLMap invariant: blocks in a cell never overlap, whatever the points") {
  MLMap map(kCell);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> xy(0.0, 0.3);
  std::uniform_real_distribution<double> z(-0.5, 3.0);
  std::uniform_real_distribution<double> variance(1e-6, 1e-2);
  for (int k = 0; k < 20000; ++k) {
    map.insert(Point(xy(random), xy(random), z(random)), variance(random));
    if (k % 997 == 0) checkCellInvariants(map);
  }
  checkCellInvariants(map);
  map.compact();
  checkCellInvariants(map);
}

TEST_CASE("MLMap invariant: the order of a flat floor's points does not change its block count") {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> xy(-2.0, 2.0);
  // Bounded noise: a Gaussian tail past 3 sigma would rightly turn a few cells vertical.
  std::uniform_real_distribution<double> noise(-0.01, 0.01);
  std::vector<Point> floor;
  for (int k = 0; k < 50000; ++k) floor.emplace_back(xy(random), xy(random), noise(random));
  MLMap in_order(kCell);
  for (const auto& p : floor) in_order.insert(p, kVar);
  std::shuffle(floor.begin(), floor.end(), random);
  MLMap shuffled(kCell);
  for (const auto& p : floor) shuffled.insert(p, kVar);
  CHECK(in_order.blockCount() == shuffled.blockCount());
  CHECK(in_order.blockCount() == in_order.cellCount());  // one horizontal block per cell
  CHECK(in_order.stats().vertical_blocks == 0);
}

TEST_CASE("MLMap: cell lookup agrees with a brute-force search") {
  MLMap map(0.05);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(-30.0, 30.0);
  std::vector<CellIndex> inserted;
  for (int k = 0; k < 30000; ++k) {
    const Point p(coordinate(random), coordinate(random), 0.0);
    map.insert(p, kVar);
    inserted.push_back(map.cellOf(p.x(), p.y()));
  }
  for (int k = 0; k < 2000; ++k) {
    const CellIndex query = map.cellOf(coordinate(random), coordinate(random));
    const bool brute_force = std::find(inserted.begin(), inserted.end(), query) != inserted.end();
    const auto number = map.cellNumber(query);
    REQUIRE(number.has_value() == brute_force);
    if (number) CHECK(map.cellAt(*number) == query);
  }
}

TEST_CASE("MLMap insertBlock: a horizontal block fuses, a vertical one joins what it reaches") {
  MLMap map(kCell);
  const CellIndex cell{0, 0};
  map.insertBlock(cell, Block{0.0F, 1e-4F, 0.0F, 0, BlockKind::Horizontal, {}});
  map.insertBlock(cell, Block{0.01F, 1e-4F, 0.0F, 0, BlockKind::Horizontal, {}});
  REQUIRE(map.blocks(cell).size() == 1);
  CHECK(map.blocks(cell)[0].height == doctest::Approx(0.005));
  map.insertBlock(cell, Block{1.0F, 1e-4F, 0.0F, 0, BlockKind::Horizontal, {}});
  map.insertBlock(cell, Block{2.0F, 1e-4F, 0.0F, 0, BlockKind::Horizontal, {}});
  REQUIRE(map.blocks(cell).size() == 3);
  // A wall section from 0.5 to 1.95 reaches the blocks at 1.0 and 2.0, not the floor.
  map.insertBlock(cell, Block{1.95F, 1e-4F, 1.45F, 0, BlockKind::Vertical, {}});
  const auto blocks = map.blocks(cell);
  REQUIRE(blocks.size() == 2);
  CHECK(blocks[1].isVertical());
  CHECK(blocks[1].height == doctest::Approx(2.0));
  CHECK(blocks[1].bottom() == doctest::Approx(0.5));
  CHECK_THROWS_AS(map.insertBlock(cell, Block{0.0F, 0.0F, 0.0F, 0, BlockKind::Horizontal, {}}),
                  mlmap::Error);
}

TEST_CASE("MLMap insertScan gives exactly the blocks of point-by-point insertion") {
  std::mt19937 random(9);
  std::uniform_real_distribution<double> xy(-1.0, 1.0);
  std::uniform_real_distribution<double> z(0.0, 2.5);
  std::normal_distribution<double> noise(0.0, 0.01);
  mlmap::Scan scan;
  scan.pose = Eigen::Translation3d(0.3, -0.2, 0.5) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ());
  for (int k = 0; k < 20000; ++k) {
    scan.points.emplace_back(xy(random), xy(random), noise(random));           // floor
    scan.points.emplace_back(xy(random), xy(random), 2.0 + noise(random));     // ceiling
    scan.points.emplace_back(0.5 + noise(random), xy(random), z(random));      // wall
    scan.points.emplace_back(xy(random) * 0.3, xy(random) * 0.3, 0.7 + noise(random));  // table
    scan.variances.insert(scan.variances.end(), 4, 1e-4);
  }
  MLMap by_scan(kCell);
  by_scan.insertScan(scan);
  MLMap by_point(kCell);
  for (std::size_t k = 0; k < scan.size(); ++k) by_point.insert(scan.worldPoint(k), scan.variance(k));
  REQUIRE(by_scan.blockCount() == by_point.blockCount());
  REQUIRE(by_scan.cellCount() == by_point.cellCount());
  for (std::size_t n = 0; n < by_point.cellCount(); ++n) {
    const auto expected = by_point.blocksAt(n);
    const auto actual = by_scan.blocks(by_point.cellAt(n));
    REQUIRE(actual.size() == expected.size());
    for (std::size_t k = 0; k < expected.size(); ++k) {
      CHECK(actual[k].height == expected[k].height);
      CHECK(actual[k].depth == expected[k].depth);
      CHECK(actual[k].variance == expected[k].variance);
      CHECK(actual[k].kind == expected[k].kind);
    }
  }
  CHECK(by_scan.stats().vertical_blocks > 0);
}
