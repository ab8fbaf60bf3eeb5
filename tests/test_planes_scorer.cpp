// eRMSM internals: the indexed plane score against a brute-force pass over every
// block, the eRMSM view of a cell's block stack, and fine maps end to end.
#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <random>

#include "../src/planes/plane_scorer.hpp"
#include "../src/planes/smallest_axis.hpp"
#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/direction_vectors.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

struct BruteScore {
  double score = 0.0;
  double similar = 0.0;
  std::vector<std::uint32_t> matching;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();  // of the matching blocks' PCA points, relative to the plane's point
};

BruteScore bruteForce(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                      const std::vector<std::uint8_t>& taken, const CandidatePlane& plane, double epsilon,
                      double kappa) {
  BruteScore result;
  PcaSums pca;
  for (std::uint32_t id = 0; id < grid.size(); ++id) {
    if (taken[id] != 0 || directions[id].squaredNorm() == 0.0F) continue;
    if (std::abs(directions[id].dot(plane.normal)) < std::cos(kappa)) continue;
    const PlaneBlock& block = grid.blocks()[id];
    result.similar += block.surface;
    if (std::abs(plane.normal.dot(block.point - plane.point)) >= epsilon) continue;
    result.score += block.surface;
    result.matching.push_back(id);
    pca.addBlock((block.point - plane.point).cast<double>(), block.vertical ? 0.5 * (block.top - block.bottom) : 0.0,
                 block.surface);
  }
  if (pca.weight > 0.0) result.mean = pca.mean();
  return result;
}

// A room with a tilted ramp, a table and noise: blocks in many orientation bins.
test::PlaneSceneBuilder scorerScene() {
  test::PlaneSceneBuilder scene(0.05, 0.01, 3);
  scene.floor(0.0, 0.0, 4.0, 3.0, 0.0).wallX(0.0, 0.0, 3.0, 0.0, 2.5).wallY(3.0, 0.0, 4.0, 0.0, 2.5);
  scene.floor(1.0, 1.0, 2.0, 1.6, 0.72);
  scene.rectangle({2.5, 0.2, 0.0}, {1.2, 0.0, 0.5}, {0.0, 1.0, 0.0}, 0.02);  // a ramp, 22.6°
  scene.rectangle({3.5, 2.0, 0.0}, {0.3, 0.5, 0.0}, {0.0, 0.0, 1.0}, 0.02);  // a diagonal board
  return scene;
}

// Direction vectors as a plain scalar pass computes them: a branch per neighbour and
// Eigen's full computeDirect (3×3) or iterative solver (2×2).
std::vector<Eigen::Vector3f> scalarDirections(const BlockGrid& grid, int radius, float height_tolerance) {
  std::vector<Eigen::Vector3f> directions(grid.size(), Eigen::Vector3f::Zero());
  const double min_spread = 0.1 * grid.cellSize() * grid.cellSize();
  const auto& blocks = grid.blocks();
  for (std::size_t cell = 0; cell < grid.cellCount(); ++cell) {
    for (std::uint32_t id = grid.firstBlockOfCell(cell); id < grid.firstBlockOfCell(cell + 1); ++id) {
      const PlaneBlock& self = blocks[id];
      const Eigen::Vector3f& centre = blocks[grid.firstBlockOfCell(cell)].point;
      float n = 0.0F, sx = 0.0F, sy = 0.0F, sz = 0.0F, xx = 0.0F, xy = 0.0F, xz = 0.0F, yy = 0.0F, yz = 0.0F, zz = 0.0F;
      grid.forEachNeighbour(self.cell, radius, [&](std::uint32_t other_id) {
        const PlaneBlock& other = blocks[other_id];
        if (other.vertical != self.vertical) return;
        if (self.vertical ? (other.bottom > self.top || other.top < self.bottom)
                          : std::abs(other.top - self.top) >= height_tolerance) {
          return;
        }
        const float dx = other.point.x() - centre.x();
        const float dy = other.point.y() - centre.y();
        const float z = other.point.z() - self.point.z();
        n += 1.0F;
        sx += dx;
        sy += dy;
        sz += z;
        xx += dx * dx;
        xy += dx * dy;
        xz += dx * z;
        yy += dy * dy;
        yz += dy * z;
        zz += z * z;
      });
      if (self.vertical) {
        if (n < 2.0F) continue;
        const Eigen::Vector2d mean = Eigen::Vector2d(sx, sy) / n;
        Eigen::Matrix2d covariance;
        covariance << xx, xy, xy, yy;
        covariance = covariance / n - mean * mean.transpose();
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver;
        solver.computeDirect(covariance);
        if (solver.eigenvalues()(1) < min_spread) continue;
        const Eigen::Vector2d normal = solver.eigenvectors().col(0);
        directions[id] = orientConsistently(Eigen::Vector3f(static_cast<float>(normal.x()), static_cast<float>(normal.y()), 0.0F));
      } else {
        if (n < 3.0F) continue;
        const Eigen::Vector3d mean = Eigen::Vector3d(sx, sy, sz) / n;
        Eigen::Matrix3d covariance;
        covariance << xx, xy, xz, xy, yy, yz, xz, yz, zz;
        covariance = covariance / n - mean * mean.transpose();
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
        solver.computeDirect(covariance);
        if (solver.eigenvalues()(1) < min_spread) continue;
        directions[id] = orientConsistently(solver.eigenvectors().col(0).cast<float>());
      }
    }
  }
  return directions;
}

}  // namespace

TEST_CASE("PlaneScorer: scores, similar surfaces and matching blocks equal a brute-force pass, before and after takes") {
  test::PlaneSceneBuilder scene = scorerScene();
  const BlockGrid grid(scene.map());
  DirectionConfig direction_config;
  direction_config.height_tolerance = 0.05F;
  const std::vector<Eigen::Vector3f> directions = directionVectors(grid, direction_config);
  const double epsilon = 0.05;
  const double kappa = 25.0 * M_PI / 180.0;
  PlaneScorer scorer(grid, directions, epsilon, kappa);
  std::vector<std::uint8_t> taken(grid.size(), 0);
  std::mt19937 random(11);
  std::uniform_int_distribution<std::uint32_t> any_block(0, static_cast<std::uint32_t>(grid.size() - 1));
  std::normal_distribution<float> tilt(0.0F, 0.05F);
  auto check = [&](int planes) {
    for (int k = 0; k < planes; ++k) {
      // Planes through a block, with its direction (or a random axis) slightly tilted.
      const std::uint32_t id = any_block(random);
      Eigen::Vector3f normal = directions[id].squaredNorm() > 0.0F ? directions[id] : Eigen::Vector3f::UnitZ();
      if (k % 3 == 0) normal = Eigen::Vector3f(tilt(random), tilt(random), tilt(random)) * 20.0F;
      normal = (normal + Eigen::Vector3f(tilt(random), tilt(random), tilt(random))).normalized();
      const CandidatePlane plane{normal, grid.blocks()[id].point};
      const PlaneScore fast = scorer.score(plane);
      const BruteScore slow = bruteForce(grid, directions, taken, plane, epsilon, kappa);
      CAPTURE(k);
      CHECK(fast.score == doctest::Approx(slow.score).epsilon(1e-6));
      CHECK(fast.similar == doctest::Approx(slow.similar).epsilon(1e-6));
      CHECK(scorer.matching(plane) == slow.matching);
      if (!slow.matching.empty()) CHECK((fast.pca.mean() - slow.mean).norm() < 1e-4);
      for (const std::uint32_t other : slow.matching) CHECK(scorer.matches(other, plane));
    }
  };
  check(300);
  // Take the floor and a wall (as accepted planes would be), then every third block.
  for (const CandidatePlane& plane : {CandidatePlane{Eigen::Vector3f::UnitZ(), Eigen::Vector3f::Zero()},
                                      CandidatePlane{Eigen::Vector3f::UnitX(), Eigen::Vector3f::Zero()}}) {
    const std::vector<std::uint32_t> ids = scorer.matching(plane);
    REQUIRE(ids.size() > 100);
    scorer.take(ids);
    for (const std::uint32_t id : ids) taken[id] = 1;
  }
  std::vector<std::uint32_t> thirds;
  for (std::uint32_t id = 0; id < grid.size(); id += 3) thirds.push_back(id);
  scorer.take(thirds);
  for (const std::uint32_t id : thirds) taken[id] = 1;
  for (std::uint32_t id = 0; id < grid.size(); ++id) CHECK(scorer.taken(id) == (taken[id] != 0));
  check(300);
}

TEST_CASE("BlockGrid: a wall's stack of short blocks between scan lines is one vertical eRMSM block per cell") {
  // 2 cm cells, scan lines 4 cm apart on the wall: the map keeps a stack of blocks per cell.
  MLMap map(0.02);
  for (int line = 0; line <= 50; ++line) {
    for (int step = 0; step <= 200; ++step) map.insert(Point(1.011, 0.005 * step, 0.04 * line), 1e-4);
  }
  std::size_t map_blocks_in_a_cell = map.blocks(map.cellOf(1.011, 0.5)).size();
  REQUIRE(map_blocks_in_a_cell > 5);
  const BlockGrid stacked(map, BlockGridConfig{0.06, 0.05});
  const BlockGrid plain(map);
  CHECK(plain.size() == map.blockCount());
  CHECK(stacked.size() == map.cellCount());
  for (const PlaneBlock& block : stacked.blocks()) {
    CHECK(block.vertical);
    CHECK(std::abs(block.bottom) < 1e-5);
    CHECK(block.top == doctest::Approx(2.0).epsilon(1e-5));
    CHECK(block.surface == doctest::Approx(2.0 / 0.02).epsilon(1e-4));
    CHECK(block.map_first == 0);
    CHECK(block.map_count == map.blocks(block.cell).size());
  }
}

TEST_CASE("BlockGrid: two level blocks of a cell either side of the noise are one level block at their weighted height") {
  MLMap map(0.02);
  // Nine points at 0.0 and one 3 cm below: two horizontal blocks in one cell.
  for (int k = 0; k < 9; ++k) map.insert(Point(0.01, 0.01, 0.0), 1e-4);
  map.insert(Point(0.01, 0.01, -0.03), 1e-4);
  REQUIRE(map.blockCount() == 2);
  const BlockGrid grid(map, BlockGridConfig{0.06, 0.05});
  REQUIRE(grid.size() == 1);
  const PlaneBlock& block = grid.blocks()[0];
  CHECK_FALSE(block.vertical);
  CHECK(block.surface == 1.0F);
  CHECK(block.map_count == 2);
  // Weights 1/σ²: the nine-point block outweighs the stray one nine to one.
  CHECK(std::abs(block.point.z() + 0.003) < 1e-4);
}

TEST_CASE("eRMSM: at 2 cm cells a wall seen every 4 cm and a noisy floor are two planes, every block labelled") {
  test::PlaneSceneBuilder scene(0.02, 0.01, 5);
  scene.floor(0.0, 0.0, 2.0, 2.0, 0.0);
  MLMap& map = scene.map();
  for (int line = 0; line <= 50; ++line) {
    for (int step = 0; step <= 400; ++step) map.insert(Point(2.013, 0.005 * step, 0.04 * line + 0.02), 1e-4);
  }
  const PlaneDetection detection = detectPlanes(map);
  REQUIRE(detection.planes.size() == 2);
  int walls = 0;
  for (const Plane& plane : detection.planes) {
    const double tilt = std::acos(std::min(1.0, std::abs(plane.normal.z()))) * 180.0 / M_PI;
    if (plane.label == PlaneClass::Wall) {
      ++walls;
      CHECK(std::abs(plane.normal.x()) > std::cos(1.0 * M_PI / 180.0));
      CHECK(std::abs(std::abs(plane.offset) - 2.013) < 0.02);
    } else {
      CHECK(plane.label == PlaneClass::Floor);
      CHECK(tilt < 1.0);
      CHECK(std::abs(plane.offset) < 0.01);
    }
  }
  CHECK(walls == 1);
  // The wall's stacked map blocks all carry its label.
  const std::int32_t wall_id =
      detection.planes[0].label == PlaneClass::Wall ? detection.planes[0].id : detection.planes[1].id;
  for (const Block& block : map.blocks(map.cellOf(2.013, 1.0))) CHECK(block.plane == wall_id);
}

TEST_CASE("BlockGrid: a ladder of single scan lines up a cell is one vertical block, a few far-apart blocks are not") {
  // 5 cm cells, scan lines 12 cm apart: every line is its own one-point level block.
  MLMap map(0.05);
  for (int line = 0; line < 10; ++line) map.insert(Point(0.02, 0.02, 0.1 + 0.12 * line), 1e-4);
  for (int line = 0; line < 4; ++line) map.insert(Point(0.22, 0.02, 0.1 + 0.12 * line), 1e-4);
  REQUIRE(map.blocks(map.cellOf(0.02, 0.02)).size() == 10);
  const BlockGridConfig config{.stack_gap = 0.06, .level_band = 0.05, .ladder_gap = 0.2, .ladder_blocks = 6,
                               .rung_variance = 1e-5};
  const BlockGrid grid(map, config);
  REQUIRE(grid.size() == 1 + 4);
  const PlaneBlock& ladder = grid.blocks()[grid.firstBlockOfCell(*map.cellNumber(map.cellOf(0.02, 0.02)))];
  CHECK(ladder.vertical);
  CHECK(ladder.bottom == doctest::Approx(0.1).epsilon(1e-5));
  CHECK(ladder.top == doctest::Approx(1.18).epsilon(1e-5));
  CHECK(ladder.surface == doctest::Approx(1.08 / 0.05).epsilon(1e-4));
  CHECK(ladder.map_count == 10);
  // Four rungs are fewer than a ladder needs: four level blocks.
  const auto four = *map.cellNumber(map.cellOf(0.22, 0.02));
  for (std::uint32_t id = grid.firstBlockOfCell(four); id < grid.firstBlockOfCell(four + 1); ++id) {
    CHECK_FALSE(grid.blocks()[id].vertical);
  }
  // Without ladders the ten stay apart.
  CHECK(BlockGrid(map, BlockGridConfig{.stack_gap = 0.06, .level_band = 0.05}).size() == 10 + 4);
}

TEST_CASE("BlockGrid: a table top fused from many points is no rung of the sparse ladder below it") {
  MLMap map(0.05);
  for (int line = 0; line < 6; ++line) map.insert(Point(0.02, 0.02, 0.05 + 0.12 * line), 1e-4);
  for (int k = 0; k < 50; ++k) map.insert(Point(0.02, 0.02, 0.80), 1e-4);  // the top, 15 cm above the last rung
  const BlockGridConfig config{.stack_gap = 0.06, .level_band = 0.05, .ladder_gap = 0.2, .ladder_blocks = 6,
                               .rung_variance = 1e-5};
  const BlockGrid grid(map, config);
  REQUIRE(grid.size() == 2);
  CHECK(grid.blocks()[0].vertical);
  CHECK(grid.blocks()[0].map_count == 6);
  CHECK_FALSE(grid.blocks()[1].vertical);
  CHECK(grid.blocks()[1].top == doctest::Approx(0.80).epsilon(1e-5));
}

TEST_CASE("eRMSM: a wall seen by scan lines 12 cm apart at 5 cm cells is found, through its ladders") {
  // Every line is a one-point level block per cell: without ladders no vertical block.
  test::PlaneSceneBuilder scene(0.05, 0.005, 11);
  scene.floor(0.0, 0.0, 3.0, 3.0, 0.0);
  MLMap& map = scene.map();
  std::mt19937 random(4);
  std::normal_distribution<double> noise(0.0, 0.005);
  for (int line = 0; line < 20; ++line) {
    for (int step = 0; step < 60; ++step) map.insert(Point(3.013 + noise(random), 0.05 * step + 0.025, 0.1 + 0.12 * line), 1e-4);
  }
  const auto walls = [](const PlaneDetection& detection) {
    std::vector<Plane> found;
    for (const Plane& plane : detection.planes)
      if (plane.label == PlaneClass::Wall) found.push_back(plane);
    return found;
  };
  // Neither ladders nor the sparse search (sparse_search.hpp, which measures its
  // neighbourhoods in metres and so finds the lines without ladders): no wall.
  ErmsmConfig without;
  without.ladder_gap = 0.0;
  without.sparse_gap = 0.0;
  CHECK(walls(detectPlanes(map, without)).empty());
  ErmsmConfig sparse_only;
  sparse_only.ladder_gap = 0.0;
  CHECK(walls(detectPlanes(map, sparse_only)).size() == 1);
  const std::vector<Plane> found = walls(detectPlanes(map));
  REQUIRE(found.size() == 1);
  CHECK(std::abs(found[0].normal.x()) > std::cos(1.0 * M_PI / 180.0));
  CHECK(std::abs(std::abs(found[0].offset) - 3.013) < 0.03);
  CHECK(found[0].area > 0.8 * 3.0 * 2.3);
}

TEST_CASE("directionVectors: the directions of a scalar pass with Eigen's solvers, and bit for bit the same at 1 and 2 threads") {
  test::PlaneSceneBuilder scene = scorerScene();
  const BlockGrid grid(scene.map());
  const std::vector<Eigen::Vector3f> expected = scalarDirections(grid, 2, 0.05F);
  std::size_t directed = 0;
  for (const Eigen::Vector3f& direction : expected) directed += direction.squaredNorm() > 0.0F ? 1 : 0;
  REQUIRE(directed > grid.size() / 2);
  std::vector<std::vector<Eigen::Vector3f>> runs;
  for (const int threads : {1, 2}) {
    DirectionConfig config;
    config.height_tolerance = 0.05F;
    config.corners = false;  // the scalar pass is Fig. 4's principal axis everywhere
    config.threads = threads;
    runs.push_back(directionVectors(grid, config));
  }
  REQUIRE(runs[0].size() == expected.size());
  // The sums are taken column by column and the level blocks' axes come from
  // smallestAxis, not computeDirect: equal up to rounding. So is the sign, but where two
  // components tie in size (a diagonal wall's normal), which one picks it.
  double worst = 0.0;
  std::size_t mismatched = 0;
  std::size_t flipped_off_tie = 0;
  for (std::size_t id = 0; id < expected.size(); ++id) {
    const bool has = runs[0][id].squaredNorm() > 0.0F;
    if (has != (expected[id].squaredNorm() > 0.0F)) ++mismatched;
    if (!has || expected[id].squaredNorm() == 0.0F) continue;
    const Eigen::Vector3f& axis = expected[id];
    const float same = (runs[0][id] - axis).norm();
    const float opposite = (runs[0][id] + axis).norm();
    worst = std::max(worst, static_cast<double>(std::min(same, opposite)));
    const Eigen::Vector3f size = axis.cwiseAbs();
    const bool tie = std::abs(size.x() - size.y()) < 1e-5F || std::abs(size.z() - size.maxCoeff()) < 1e-5F;
    if (opposite < same && !tie) ++flipped_off_tie;
  }
  CHECK(mismatched == 0);
  CHECK(worst < 1e-4);  // 0.006°
  CHECK(flipped_off_tie == 0);
  CHECK(std::memcmp(runs[0].data(), runs[1].data(), runs[0].size() * sizeof(Eigen::Vector3f)) == 0);
}

TEST_CASE("smallestAxis: Eigen's smallest eigenvector and middle eigenvalue, surfaces and degenerate spreads alike") {
  std::mt19937 random(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  // Covariances R·diag(λ)·Rᵀ: a level surface's (λ far apart), a line's and a blob's
  // (the two smallest equal: computeDirect's answer), a point's (all zero).
  const std::vector<Eigen::Vector3d> spectra{{1e-6, 4e-4, 4e-4}, {1e-8, 1e-4, 9e-4}, {0.0, 0.02, 0.03},
                                             {2e-4, 2e-4, 8e-4}, {1e-4, 1e-4, 1e-4}, {0.0, 0.0, 0.0}};
  for (const Eigen::Vector3d& spectrum : spectra) {
    for (int trial = 0; trial < 50; ++trial) {
      const Eigen::Quaterniond rotation =
          Eigen::Quaterniond(normal(random), normal(random), normal(random), normal(random)).normalized();
      const Eigen::Matrix3d turn = rotation.toRotationMatrix();
      const Eigen::Matrix3d covariance = turn * spectrum.asDiagonal() * turn.transpose();
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
      solver.computeDirect(covariance);
      const SmallestAxis smallest = smallestAxis(covariance);
      CAPTURE(spectrum.transpose());
      CHECK(std::abs(smallest.axis.norm() - 1.0) < 1e-12);
      // Of two equal eigenvalues, both solvers take a square root of a discriminant near
      // zero: 1e-8 relative apart at worst.
      CHECK(std::abs(smallest.middle_eigenvalue - solver.eigenvalues()(1)) <= 1e-7 * std::max(spectrum(2), 1e-12));
      // The axis is only defined when the smallest eigenvalue stands apart.
      if (spectrum(1) - spectrum(0) > 1e-3 * spectrum(2)) {
        CHECK(std::abs(smallest.axis.dot(solver.eigenvectors().col(0))) > 1.0 - 1e-12);
        CHECK(std::abs(smallest.axis.dot(turn.col(0))) > 1.0 - 1e-9);
      }
    }
  }
}

TEST_CASE("BlockGrid: forEachInCells visits exactly the blocks of the box's cells, in ascending ids, boxes beyond the map too") {
  test::PlaneSceneBuilder scene = scorerScene();
  const BlockGrid grid(scene.map());
  REQUIRE(grid.size() > 1000);
  struct Box {
    std::int64_t i_low, i_high, j_low, j_high;
  };
  // Inside, straddling the map's edge, wholly outside, empty (low > high), one cell, huge,
  // and the map's rows but columns wholly right or left of it.
  const std::vector<Box> boxes{{10, 30, 5, 40},  {-20, 3, 70, 200},  {500, 600, 500, 600},
                               {20, 10, 5, 40},  {12, 12, 12, 12},   {-(std::int64_t{1} << 40), std::int64_t{1} << 40, -5, 5},
                               {0, 80, 300, 301}, {0, 80, -40, -30}, {0, 80, 82, 82}};
  for (const Box& box : boxes) {
    CAPTURE(box.i_low);
    CAPTURE(box.j_low);
    std::vector<std::uint32_t> expected;
    for (std::uint32_t id = 0; id < grid.size(); ++id) {
      const CellIndex cell = grid.blocks()[id].cell;
      if (cell.i >= box.i_low && cell.i <= box.i_high && cell.j >= box.j_low && cell.j <= box.j_high) expected.push_back(id);
    }
    std::vector<std::uint32_t> visited;
    grid.forEachInCells(box.i_low, box.i_high, box.j_low, box.j_high, [&](std::uint32_t id) { visited.push_back(id); });
    CHECK(visited == expected);
  }
}
