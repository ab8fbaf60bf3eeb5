// eRMSM internals for speed: the grid's row-by-row block numbering and its neighbour
// runs, the patch split over raster column runs, outlines independent of block order,
// and the counting sort — each against a plain reference.
#include <doctest/doctest.h>

#include <algorithm>
#include <map>
#include <numbers>
#include <numeric>
#include <random>
#include <set>

#include "../src/planes/counting_sort.hpp"
#include "../src/planes/outline_runs.hpp"
#include "../src/planes/patch_rules.hpp"
#include "../src/planes/plane_scorer.hpp"
#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/direction_vectors.hpp"
#include "mlmap/planes/patches.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

// Walls (vertical blocks), a floor with holes and a table: many patches on any plane.
test::PlaneSceneBuilder patchScene() {
  test::PlaneSceneBuilder scene(0.05, 0.005, 7);
  scene.floor(0.0, 0.0, 1.2, 0.4, 0.0).floor(0.0, 0.6, 1.2, 1.0, 0.0).floor(0.5, 0.42, 0.55, 0.58, 0.0);
  scene.floor(1.4, 0.2, 1.9, 0.7, 0.0).floor(0.3, 0.3, 0.8, 0.6, 0.72);
  scene.wallX(0.02, 0.0, 1.0, 0.0, 1.2).wallY(1.01, 0.0, 0.7, 0.3, 1.5).wallY(1.03, 0.9, 1.6, 0.0, 0.8);
  return scene;
}

// Connected components the slow way: every raster cell of every block (on a level
// plane its map cell; else its point's, and for a vertical block those of points along
// its extent a cell apart), cells within gap_cells (Chebyshev) connected; patches in
// the order of their first block, largest first.
std::vector<std::vector<std::uint32_t>> referencePatches(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                                         const Eigen::Vector3d& normal, const Eigen::Vector3d& point,
                                                         int gap_cells) {
  Eigen::Vector3d u_axis;
  Eigen::Vector3d v_axis;
  planeBasis(normal, u_axis, v_axis);
  const double cell = grid.cellSize();
  auto cellOf = [&](const Eigen::Vector3d& p) {
    return std::pair<int, int>(static_cast<int>(std::floor((p - point).dot(u_axis) / cell)),
                               static_cast<int>(std::floor((p - point).dot(v_axis) / cell)));
  };
  std::map<std::pair<int, int>, std::size_t> cell_number;
  std::vector<std::pair<int, int>> cells;
  std::vector<std::size_t> first_cell(blocks.size());
  auto add = [&](const std::pair<int, int>& c) {
    const auto [it, fresh] = cell_number.emplace(c, cells.size());
    if (fresh) cells.push_back(c);
    return it->second;
  };
  const bool level = std::abs(normal.z()) > 0.96;  // within 16° of level
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const PlaneBlock& block = grid.blocks()[blocks[k]];
    const Eigen::Vector3d centre = block.point.cast<double>();
    first_cell[k] = add(level ? std::pair<int, int>(block.cell.i, block.cell.j) : cellOf(centre));
    if (level || !block.vertical) continue;
    const double depth = block.top - block.bottom;
    const int steps = std::max(1, static_cast<int>(std::ceil(depth / cell)));
    for (int s = 0; s <= steps; ++s) add(cellOf({centre.x(), centre.y(), block.bottom + depth * s / steps}));
  }
  std::vector<std::size_t> component(cells.size());
  std::iota(component.begin(), component.end(), std::size_t{0});
  // Relabel until stable: each cell takes the smallest label within reach.
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t a = 0; a < cells.size(); ++a) {
      for (int du = -gap_cells; du <= gap_cells; ++du) {
        for (int dv = -gap_cells; dv <= gap_cells; ++dv) {
          const auto it = cell_number.find({cells[a].first + du, cells[a].second + dv});
          if (it == cell_number.end() || component[it->second] <= component[a]) continue;
          component[it->second] = component[a];
          changed = true;
        }
      }
    }
  }
  std::vector<std::vector<std::uint32_t>> patches;
  std::vector<double> surfaces;
  std::map<std::size_t, std::size_t> patch_of;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const auto [it, fresh] = patch_of.emplace(component[first_cell[k]], patches.size());
    if (fresh) {
      patches.emplace_back();
      surfaces.push_back(0.0);
    }
    patches[it->second].push_back(blocks[k]);
    surfaces[it->second] += grid.blocks()[blocks[k]].surface;
  }
  std::vector<std::size_t> order(patches.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return surfaces[a] > surfaces[b]; });
  std::vector<std::vector<std::uint32_t>> sorted;
  for (const std::size_t k : order) sorted.push_back(patches[k]);
  return sorted;
}

// withEdges the slow way: rings round the plane's blocks until none joins.
std::vector<std::uint32_t> referenceEdges(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                                          const PlaneScorer& scorer, const std::vector<std::uint32_t>& matching,
                                          const CandidatePlane& plane, double epsilon, double kappa) {
  std::set<std::uint32_t> in_plane(matching.begin(), matching.end());
  const auto cos_edge = static_cast<float>(std::cos(std::min(2.0 * kappa, std::numbers::pi / 2)));
  std::vector<std::uint32_t> frontier = matching;
  while (!frontier.empty()) {
    std::vector<std::uint32_t> next;
    for (const std::uint32_t id : frontier) {
      grid.forEachNeighbour(grid.blocks()[id].cell, 1, [&](std::uint32_t other) {
        if (in_plane.count(other) != 0 || scorer.taken(other)) return;
        const Eigen::Vector3f& direction = directions[other];
        if (direction.squaredNorm() > 0.0F && std::abs(direction.dot(plane.normal)) < cos_edge) return;
        if (std::abs(plane.normal.dot(grid.blocks()[other].point - plane.point)) >= static_cast<float>(epsilon)) return;
        in_plane.insert(other);
        next.push_back(other);
      });
    }
    frontier = std::move(next);
  }
  return {in_plane.begin(), in_plane.end()};
}

}  // namespace

TEST_CASE("withEdges: the edge blocks found from the scorer's index equal rings grown round the plane, before and after takes") {
  test::PlaneSceneBuilder scene = patchScene();
  scene.rectangle({1.5, 0.9, 0.0}, {0.5, 0.0, 0.3}, {0.0, 0.5, 0.0}, 0.01);  // a ramp, its edges bent
  const BlockGrid grid(scene.map());
  DirectionConfig direction_config;
  const std::vector<Eigen::Vector3f> directions = directionVectors(grid, direction_config);
  const double epsilon = 0.05;
  const double kappa = 25.0 * std::numbers::pi / 180.0;
  PlaneScorer scorer(grid, directions, epsilon, kappa);
  const std::vector<CandidatePlane> planes{{Eigen::Vector3f::UnitZ(), {0.0F, 0.0F, 0.0F}},
                                           {Eigen::Vector3f::UnitZ(), {0.0F, 0.0F, 0.72F}},
                                           {Eigen::Vector3f::UnitX(), {0.02F, 0.0F, 0.0F}},
                                           {Eigen::Vector3f::UnitY(), {0.0F, 1.02F, 0.0F}},
                                           {Eigen::Vector3f(-0.51F, 0.0F, 0.86F).normalized(), {1.5F, 0.9F, 0.0F}}};
  std::size_t grown = 0;
  for (int round = 0; round < 2; ++round) {
    for (const CandidatePlane& plane : planes) {
      const std::vector<std::uint32_t> matching = scorer.matching(plane);
      const std::vector<std::uint32_t> edges = withEdges(grid, directions, scorer, matching, plane, epsilon, kappa);
      CHECK(edges == referenceEdges(grid, directions, scorer, matching, plane, epsilon, kappa));
      grown += edges.size() - matching.size();
    }
    scorer.take(scorer.matching(planes[0]));  // the floor leaves the pool
  }
  CHECK(grown > 0);
}

TEST_CASE("BlockGrid: blocks numbered row by row, a Chebyshev window's blocks visited in ascending ids, map order kept, filtered") {
  test::PlaneSceneBuilder scene = patchScene();
  const MLMap& map = scene.map();
  const BlockGrid grid(map);
  const auto& blocks = grid.blocks();
  REQUIRE(grid.size() == map.blockCount());
  for (std::uint32_t id = 1; id < grid.size(); ++id) {
    const CellIndex a = blocks[id - 1].cell;
    const CellIndex b = blocks[id].cell;
    CHECK((a.i < b.i || (a.i == b.i && a.j < b.j) || (a.i == b.i && a.j == b.j && blocks[id - 1].top <= blocks[id].top)));
  }
  for (std::uint32_t id = 0; id < grid.size(); id += 7) {
    for (const int radius : {1, 2, 4}) {
      std::vector<std::uint32_t> visited;
      grid.forEachNeighbour(blocks[id].cell, radius, [&](std::uint32_t other) { visited.push_back(other); });
      std::vector<std::uint32_t> expected;
      for (std::uint32_t other = 0; other < grid.size(); ++other) {
        if (std::abs(blocks[other].cell.i - blocks[id].cell.i) <= radius &&
            std::abs(blocks[other].cell.j - blocks[id].cell.j) <= radius) {
          expected.push_back(other);
        }
      }
      CHECK(visited == expected);
    }
  }
  // Cell numbers map back to the map's cells, and idsInMapOrder lists the blocks by the map's cell numbers.
  std::vector<std::uint32_t> in_map_order = grid.idsInMapOrder();
  REQUIRE(in_map_order.size() == grid.size());
  std::vector<std::size_t> map_cell_of_block(grid.size());
  for (std::size_t n = 0; n < grid.cellCount(); ++n) {
    const std::size_t map_cell = grid.mapCellOf(n);
    CHECK(map.cellAt(map_cell) == blocks[grid.firstBlockOfCell(n)].cell);
    for (std::uint32_t id = grid.firstBlockOfCell(n); id < grid.firstBlockOfCell(n + 1); ++id) map_cell_of_block[id] = map_cell;
  }
  for (std::size_t k = 1; k < in_map_order.size(); ++k) {
    CHECK(map_cell_of_block[in_map_order[k - 1]] <= map_cell_of_block[in_map_order[k]]);
  }
  // With a flag per block, the flagged ones in the same order, on any number of threads.
  std::vector<std::uint8_t> keep(grid.size());
  for (std::uint32_t id = 0; id < grid.size(); ++id) keep[id] = id % 3 == 0 || blocks[id].vertical ? 1 : 0;
  std::vector<std::uint32_t> kept;
  for (const std::uint32_t id : in_map_order) {
    if (keep[id] != 0) kept.push_back(id);
  }
  REQUIRE(kept.size() < in_map_order.size());
  for (const int threads : {1, 2, 3}) CHECK(grid.idsInMapOrder(keep, threads) == kept);
  std::sort(in_map_order.begin(), in_map_order.end());
  for (std::uint32_t id = 0; id < grid.size(); ++id) CHECK(in_map_order[id] == id);
}

namespace {

// The planes the split tests cut the patch scene with: a wall's and a 30° ramp's (on
// the plane's own raster: a vertical block is a run of cells), a floor's and one tilted
// 10° (on the map's grid); every block, and a sparse random one in `keep_one_in` so
// that many small components form; gaps of 1 and 2 cells.
template <typename Check>
void forEachSplitCase(const BlockGrid& grid, unsigned seed, unsigned keep_one_in, Check&& check) {
  std::mt19937 random(seed);
  const std::vector<Eigen::Vector3d> normals{Eigen::Vector3d::UnitX(), Eigen::Vector3d(std::sin(0.52), 0.0, std::cos(0.52)),
                                            Eigen::Vector3d::UnitZ(), Eigen::Vector3d(std::sin(0.17), 0.0, std::cos(0.17))};
  for (const Eigen::Vector3d& normal : normals) {
    for (const bool sparse : {false, true}) {
      std::vector<std::uint32_t> blocks;
      for (std::uint32_t id = 0; id < grid.size(); ++id) {
        if (!sparse || random() % keep_one_in == 0) blocks.push_back(id);
      }
      for (const int gap : {1, 2}) check(blocks, normal, Eigen::Vector3d(0.013, -0.021, 0.007), gap);
    }
  }
}

}  // namespace

TEST_CASE("splitIntoPatches: components over raster column runs equal cell-by-cell components") {
  test::PlaneSceneBuilder scene = patchScene();
  const BlockGrid grid(scene.map());
  std::size_t most_patches = 0;
  forEachSplitCase(grid, 3, 10, [&](const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
                                    const Eigen::Vector3d& point, int gap) {
    const std::vector<Patch> patches = splitIntoPatches(grid, blocks, normal, point, gap);
    const auto expected = referencePatches(grid, blocks, normal, point, gap);
    REQUIRE(patches.size() == expected.size());
    for (std::size_t k = 0; k < patches.size(); ++k) CHECK(patches[k].blocks == expected[k]);
    most_patches = std::max(most_patches, patches.size());
  });
  CHECK(most_patches > 3);
}

TEST_CASE("splitWithOutlineRuns: each patch's runs trace the outline outlineOf traces from its blocks, at gaps 1 and 2") {
  test::PlaneSceneBuilder scene = patchScene();
  const BlockGrid grid(scene.map());
  std::size_t compared = 0;
  forEachSplitCase(grid, 9, 4, [&](const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
                                   const Eigen::Vector3d& point, int gap) {
    const SplitPatches split = splitWithOutlineRuns(grid, blocks, normal, point, gap, 2);
    const std::vector<Patch> plain = splitIntoPatches(grid, blocks, normal, point, gap);
    REQUIRE(split.patches.size() == plain.size());
    REQUIRE(split.outline_runs.size() == plain.size());
    for (std::size_t k = 0; k < plain.size(); ++k) {
      CHECK(split.patches[k].blocks == plain[k].blocks);
      const auto expected = outlineOf(grid, plain[k].blocks, normal, point);
      const auto traced = outlineOfRuns(split.outline_runs[k], grid.cellSize(), normal, point);
      REQUIRE(traced.size() == expected.size());
      for (std::size_t c = 0; c < expected.size(); ++c) CHECK(traced[c] == expected[c]);
      ++compared;
    }
  });
  CHECK(compared > 20);
}

TEST_CASE("splitWithOutlineRuns: a level plane of over 20 000 blocks splits the same on 1 to 3 threads") {
  // Three floors 10 cm apart (three patches at a gap of 2 cells), thinned at random so
  // that small pieces break off; large enough for the split's parallel passes.
  test::PlaneSceneBuilder scene(0.02, 0.0, 3);
  scene.floor(0.0, 0.0, 3.2, 3.0, 0.0).floor(3.3, 0.0, 4.0, 3.0, 0.0).floor(0.0, 3.1, 4.0, 3.6, 0.0);
  const BlockGrid grid(scene.map());
  std::mt19937 random(4);
  std::vector<std::uint32_t> blocks;
  for (std::uint32_t id = 0; id < grid.size(); ++id) {
    if (random() % 7 != 0) blocks.push_back(id);
  }
  REQUIRE(blocks.size() > 20000);
  const Eigen::Vector3d normal = Eigen::Vector3d(0.0, std::sin(0.05), std::cos(0.05));
  const Eigen::Vector3d point(1.0, 1.0, 0.0);
  const SplitPatches one = splitWithOutlineRuns(grid, blocks, normal, point, 2, 1);
  REQUIRE(one.patches.size() >= 3);
  CHECK(one.patches[2].blocks.size() > 2000);  // the three floors, then the pieces
  for (const int threads : {2, 3}) {
    const SplitPatches many = splitWithOutlineRuns(grid, blocks, normal, point, 2, threads);
    REQUIRE(many.patches.size() == one.patches.size());
    for (std::size_t k = 0; k < one.patches.size(); ++k) {
      CHECK(many.patches[k].blocks == one.patches[k].blocks);
      CHECK(many.patches[k].surface == one.patches[k].surface);
      REQUIRE(many.outline_runs[k].size() == one.outline_runs[k].size());
      for (std::size_t r = 0; r < one.outline_runs[k].size(); ++r) {
        CHECK(many.outline_runs[k][r].u == one.outline_runs[k][r].u);
        CHECK(many.outline_runs[k][r].v_low == one.outline_runs[k][r].v_low);
        CHECK(many.outline_runs[k][r].v_high == one.outline_runs[k][r].v_high);
      }
    }
  }
}

TEST_CASE("outlineOf: the same outline whatever order the blocks are listed in") {
  test::PlaneSceneBuilder scene(0.05, 0.0, 1);
  // Two squares touching at a corner, and a ragged strip: loops meet at vertices.
  scene.floor(0.0, 0.0, 0.48, 0.48, 0.0).floor(0.51, 0.51, 0.98, 0.98, 0.0);
  for (int k = 0; k < 20; ++k) scene.floor(1.2 + 0.05 * k, 0.2 * (k % 3), 1.24 + 0.05 * k, 0.2 * (k % 3) + 0.3, 0.0);
  const BlockGrid grid(scene.map());
  std::vector<std::uint32_t> blocks(grid.size());
  std::iota(blocks.begin(), blocks.end(), std::uint32_t{0});
  const Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d point(0.0, 0.0, 0.0);
  const std::vector<Eigen::Vector3d> outline = outlineOf(grid, blocks, normal, point);
  REQUIRE(outline.size() >= 8);
  std::mt19937 random(5);
  for (int trial = 0; trial < 5; ++trial) {
    std::shuffle(blocks.begin(), blocks.end(), random);
    const std::vector<Eigen::Vector3d> shuffled = outlineOf(grid, blocks, normal, point);
    REQUIRE(shuffled.size() == outline.size());
    for (std::size_t k = 0; k < outline.size(); ++k) CHECK((shuffled[k] - outline[k]).norm() < 1e-12);
  }
}

TEST_CASE("stableSortBy: a counting sort, or a stable sort for wide key ranges, equals std::stable_sort, on 1 to 3 threads") {
  std::mt19937 random(11);
  // Short lists are sorted on one thread whatever is asked; long ones in slices.
  for (const std::size_t size : {std::size_t{3000}, std::size_t{120000}}) {
    for (const std::int64_t range : {std::int64_t{5}, std::int64_t{1000}, std::int64_t{1} << 40}) {
      std::vector<std::pair<std::int64_t, std::uint32_t>> items(size);
      for (std::uint32_t k = 0; k < items.size(); ++k) {
        items[k] = {static_cast<std::int64_t>(random() % static_cast<std::uint64_t>(range)) - range / 2, k};
      }
      auto expected = items;
      std::stable_sort(expected.begin(), expected.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      for (const int threads : {1, 2, 3}) {
        CAPTURE(size);
        CAPTURE(range);
        CAPTURE(threads);
        auto sorted = items;
        stableSortBy(sorted, [](const auto& item) { return item.first; }, threads);
        CHECK(sorted == expected);
      }
    }
  }
}

TEST_CASE("spreadExceeds: the same answer as comparing directionSpread, near the limit and far from it") {
  test::PlaneSceneBuilder scene = patchScene();
  scene.rectangle({1.5, 0.9, 0.0}, {0.5, 0.0, 0.3}, {0.0, 0.5, 0.0}, 0.01);  // a ramp, its edges bent
  const BlockGrid grid(scene.map());
  const std::vector<Eigen::Vector3f> directions = directionVectors(grid, DirectionConfig{});
  PlaneScorer scorer(grid, directions, 0.05, 25.0 * std::numbers::pi / 180.0);
  // Planes tilted off the blocks' directions, so the angles are neither 0 nor alike.
  const std::vector<CandidatePlane> planes{{Eigen::Vector3f(0.05F, 0.0F, 1.0F).normalized(), {0.0F, 0.0F, 0.0F}},
                                           {Eigen::Vector3f(0.0F, 0.2F, 1.0F).normalized(), {0.0F, 0.0F, 0.72F}},
                                           {Eigen::Vector3f(1.0F, 0.1F, 0.0F).normalized(), {0.02F, 0.0F, 0.0F}},
                                           {Eigen::Vector3f(-0.51F, 0.0F, 0.86F).normalized(), {1.5F, 0.9F, 0.0F}}};
  std::size_t checked = 0;
  for (const CandidatePlane& plane : planes) {
    const std::vector<std::uint32_t> ids = scorer.matching(plane);
    if (ids.empty()) continue;
    const double spread = directionSpread(grid, directions, ids, plane);
    for (const double limit : {0.0, spread * (1.0 - 1e-3), spread * (1.0 - 1e-12), spread, spread * (1.0 + 1e-12),
                               spread * (1.0 + 1e-3), std::nextafter(spread, 0.0), std::nextafter(spread, 90.0), 90.0}) {
      CHECK(spreadExceeds(grid, directions, ids, plane, limit) == (spread > limit));
      ++checked;
    }
  }
  CHECK(checked >= 18);
  CHECK_FALSE(spreadExceeds(grid, directions, {}, planes[0], 0.0));  // no blocks: no spread
}

TEST_CASE("outlineOf: holes, and islands inside them, leave the outer boundary as it is") {
  test::PlaneSceneBuilder scene(0.05, 0.0, 1);
  scene.floor(0.0, 0.0, 0.98, 0.98, 0.0);  // 20 × 20 cells
  const BlockGrid grid(scene.map());
  const Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d point(0.0, 0.0, 0.0);
  std::vector<std::uint32_t> all(grid.size());
  std::iota(all.begin(), all.end(), std::uint32_t{0});
  const std::vector<Eigen::Vector3d> full = outlineOf(grid, all, normal, point);
  REQUIRE(full.size() == 4);
  std::mt19937 random(9);
  for (int trial = 0; trial < 5; ++trial) {
    // Holes of one cell, cells touching at corners, and a ring round a one-cell island,
    // all at least two cells inside the edge.
    std::vector<std::uint32_t> kept;
    for (const std::uint32_t id : all) {
      const CellIndex cell = grid.blocks()[id].cell;
      const int ring = std::max(std::abs(cell.i - 14), std::abs(cell.j - 14));
      const bool inner = cell.i >= 2 && cell.i <= 17 && cell.j >= 2 && cell.j <= 17;
      if (ring == 1 || (inner && ring > 2 && random() % 3 == 0)) continue;
      kept.push_back(id);
    }
    const std::vector<Eigen::Vector3d> outline = outlineOf(grid, kept, normal, point);
    REQUIRE(outline.size() == full.size());
    for (std::size_t k = 0; k < full.size(); ++k) CHECK((outline[k] - full[k]).norm() < 1e-12);
  }
}

TEST_CASE("outlineOfRuns: the corners of a rectangle, an L and two cells touching at a corner, counter-clockwise about the normal") {
  using Corners = std::vector<Eigen::Vector2i>;
  // Cells of 1 m. On a wall facing +x through the origin the raster's u and v are y and
  // z: a corner (u, v) is the point (0, u, v). On a level plane the raster is the map's
  // grid, u its row (y) and v its column (x): a corner (u, v) is the point (v, u, 0),
  // and counter-clockwise about +z runs the other way round from the same corner.
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  auto corners = [&](const std::vector<Segment>& runs, const Eigen::Vector3d& normal) {
    std::vector<Eigen::Vector2i> result;
    for (const Eigen::Vector3d& corner : outlineOfRuns(runs, 1.0, normal, origin)) {
      const bool level = normal.z() != 0.0;
      CHECK(std::abs(level ? corner.z() : corner.x()) < 1e-12);
      result.emplace_back(static_cast<int>(std::lround(corner.y())),
                          static_cast<int>(std::lround(level ? corner.x() : corner.z())));
    }
    return result;
  };
  auto reversed = [](Corners loop) {
    std::reverse(loop.begin() + 1, loop.end());
    return loop;
  };
  const Eigen::Vector3d wall = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d level = Eigen::Vector3d::UnitZ();
  // Three columns of two cells.
  const Corners rectangle{{0, 0}, {3, 0}, {3, 2}, {0, 2}};
  CHECK(corners({{0, 0, 1}, {1, 0, 1}, {2, 0, 1}}, wall) == rectangle);
  // A column of three with a row of two more along its foot.
  const Corners ell{{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 3}, {0, 3}};
  CHECK(corners({{0, 0, 2}, {1, 0, 0}, {2, 0, 0}}, wall) == ell);
  // Touching at (1, 1) only: one loop round both, through that vertex twice.
  const Corners touching{{0, 0}, {1, 0}, {1, 1}, {2, 1}, {2, 2}, {1, 2}, {1, 1}, {0, 1}};
  CHECK(corners({{0, 0, 0}, {1, 1, 1}}, wall) == touching);
  // A ring of eight round a hole: the outer square only.
  const Corners ring{{0, 0}, {3, 0}, {3, 3}, {0, 3}};
  CHECK(corners({{0, 0, 2}, {1, 0, 0}, {1, 2, 2}, {2, 0, 2}}, wall) == ring);
  // The same runs on the map's grid (corners read back as (u, v) = (y, x)).
  CHECK(corners({{0, 0, 1}, {1, 0, 1}, {2, 0, 1}}, level) == reversed(rectangle));
  CHECK(corners({{0, 0, 2}, {1, 0, 0}, {2, 0, 0}}, level) == reversed(ell));
  CHECK(corners({{0, 0, 0}, {1, 1, 1}}, level) == reversed(touching));
  CHECK(corners({{0, 0, 2}, {1, 0, 0}, {1, 2, 2}, {2, 0, 2}}, level) == reversed(ring));
  // About a normal pointing down, counter-clockwise is the raster's own turn.
  CHECK(corners({{0, 0, 2}, {1, 0, 0}, {2, 0, 0}}, -level) == ell);
  CHECK(corners({}, wall).empty());
  // Cells one empty cell apart are one patch (the split's gap of 2) and one outline: a
  // wall whose raster columns alternate with empty ones (turned 41° to the grid, or seen
  // in vertical scan lines) was outlined by one column, and one with a gap between its
  // scan lines by one band. Notches and single cells a corner apart stay as they are.
  const Corners wide{{0, 0}, {5, 0}, {5, 4}, {0, 4}};
  CHECK(corners({{0, 0, 3}, {2, 0, 3}, {4, 0, 3}}, wall) == wide);
  CHECK(corners({{0, 0, 0}, {0, 2, 3}, {1, 0, 0}, {1, 2, 3}, {2, 0, 0}, {2, 2, 3}, {3, 0, 0}, {3, 2, 3}, {4, 0, 0},
                 {4, 2, 3}},
                wall) == wide);
  // Two cells two empty cells apart: two loops, the one with the lowest corner kept.
  CHECK(corners({{0, 0, 0}, {3, 0, 0}}, wall) == Corners{{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  // Diagonally opposite across an empty cell: bridged, three cells touching at corners.
  CHECK(corners({{0, 0, 0}, {2, 2, 2}}, wall).size() == 12);
}
