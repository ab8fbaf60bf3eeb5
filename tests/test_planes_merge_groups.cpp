// The coplanar merge (src/planes/patch_merges.hpp) tests the groups two patches already
// joined, not only the two: a small rough piece between a floor and a ramp passes the
// pairwise tests with each, and chained the floor and the ramp into one patch (seen on
// OctoMap's fr079 at 10 cm cells, with the search's planes in another order: the floor and
// the staircase, one patch 7° off level).
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

#include "../src/planes/patch_merges.hpp"
#include "mlmap/planes/block_grid.hpp"
#include "patch_pieces.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

constexpr double kKappa = 25.0 * std::numbers::pi / 180.0;
constexpr double kEpsilon = 0.05;
constexpr double kNoise = 0.005;

// Blocks of x < 3 m (the floor), 3-3.3 m (the rough piece) and beyond (the ramp), each
// described on its own plane, as the search leaves them.
PatchSet threePieces(const BlockGrid& grid) {
  PatchSet set;
  set.labels.assign(grid.size(), 0);
  std::vector<std::vector<std::uint32_t>> pieces(3);
  for (std::uint32_t id = 0; id < grid.size(); ++id) {
    const double x = grid.blocks()[id].point.x();
    const std::size_t piece = x < 3.0 ? 0 : x < 3.3 ? 1 : 2;
    pieces[piece].push_back(id);
  }
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const Eigen::Vector3f normal = k == 2 ? Eigen::Vector3f(-0.17F, 0.0F, 0.985F).normalized() : Eigen::Vector3f::UnitZ();
    test::addPatch(grid, set, pieces[k], normal, kKappa, kNoise);
  }
  return set;
}

}  // namespace

TEST_CASE("Coplanar merge: a rough piece does not chain a floor and a ramp into one patch") {
  for (const unsigned seed : {1U, 2U, 3U}) {
    CAPTURE(seed);
    const double slope = 10.0 * std::numbers::pi / 180.0;
    test::PlaneSceneBuilder scene(0.05, kNoise, seed);
    scene.withNoise(kNoise, 1e-4).floor(0.0, 0.0, 3.0, 2.0, 0.0);
    scene.withNoise(0.015, 1e-4).floor(3.0, 0.0, 3.3, 2.0, 0.0);
    scene.withNoise(kNoise, 1e-4)
        .rectangle(Eigen::Vector3d(3.3, 0.0, 0.0), Eigen::Vector3d(3.0 * std::cos(slope), 0.0, 3.0 * std::sin(slope)),
                   Eigen::Vector3d(0.0, 2.0, 0.0));
    const BlockGrid grid(scene.map());
    PatchSet set = threePieces(grid);
    REQUIRE(set.planes.size() == 3);
    mergeCoplanar(grid, set, kEpsilon, kKappa, kNoise);
    // The floor and the ramp stay apart; the rough piece may join either.
    REQUIRE(set.planes.size() >= 2);
    for (const Plane& plane : set.planes) CHECK(plane.rms < 0.03);
    CHECK(std::abs(set.planes.front().normal.z()) > std::cos(2.0 * std::numbers::pi / 180.0));
  }
}

TEST_CASE("Coplanar merge: two pieces of a long wall whose own fits lean apart are one wall where they meet") {
  // A wall 10 m long bent by 2° 6 m along (PCL's room_scan2 at 5 cm cells: a 10 m wall in
  // two pieces 0.8° apart, the far one's centroid 7.7 cm off the near one's plane). The far
  // piece's centroid lies 7 cm off the near piece's plane, beyond ε; where they meet, on it.
  const double bend = 2.0 * std::numbers::pi / 180.0;
  const double noise = 0.015;
  for (const unsigned seed : {1U, 2U}) {
    CAPTURE(seed);
    test::PlaneSceneBuilder scene(0.05, noise, seed);
    scene.withNoise(noise, 1e-4).wallY(0.0, 0.0, 6.0, 0.0, 2.5);
    scene.withNoise(noise, 1e-4)
        .rectangle(Eigen::Vector3d(6.0, 0.0, 0.0), Eigen::Vector3d(4.0 * std::cos(bend), 4.0 * std::sin(bend), 0.0),
                   Eigen::Vector3d(0.0, 0.0, 2.5));
    const BlockGrid grid(scene.map());
    PatchSet set;
    set.labels.assign(grid.size(), 0);
    std::vector<std::uint32_t> near, far;
    for (std::uint32_t id = 0; id < grid.size(); ++id) (grid.blocks()[id].point.x() < 6.0 ? near : far).push_back(id);
    test::addPatch(grid, set, near, Eigen::Vector3f::UnitY(), kKappa, noise);
    const Eigen::Vector3f far_normal(static_cast<float>(-std::sin(bend)), static_cast<float>(std::cos(bend)), 0.0F);
    test::addPatch(grid, set, far, far_normal, kKappa, noise);
    REQUIRE(set.planes.size() == 2);
    const Plane& first = set.planes[0];
    CHECK(std::abs(first.normal.dot(set.planes[1].centroid) + first.offset) > kEpsilon);
    mergeCoplanar(grid, set, kEpsilon, kKappa, noise);
    CHECK(set.planes.size() == 1);  // 2 before
  }
}
