// VoxelHashMap: every query against brute force, on random and structured clouds.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "helpers.hpp"
#include "mlmap/registration/voxel_hash_map.hpp"

namespace {

using mlmap::Point;
using mlmap::registration::VoxelHashMap;

std::optional<double> bruteNearest(const std::vector<Point>& cloud, const Point& query, double max_distance) {
  double best = std::numeric_limits<double>::infinity();
  for (const Point& point : cloud) best = std::min(best, (point - query).norm());
  if (best > max_distance) return std::nullopt;
  return best;
}

// Three walls of a room, a floor and a staircase, sampled on a 2 cm grid with noise.
std::vector<Point> structuredCloud(unsigned seed) {
  std::mt19937 generator(seed);
  std::normal_distribution<double> noise(0.0, 0.005);
  std::vector<Point> cloud;
  for (double a = 0.0; a < 3.0; a += 0.02) {
    for (double b = 0.0; b < 2.0; b += 0.02) {
      cloud.emplace_back(a, b, noise(generator));           // floor
      cloud.emplace_back(noise(generator), b, a * 0.8);     // wall x = 0
      cloud.emplace_back(a, noise(generator), b * 1.2);     // wall y = 0
    }
  }
  for (int step = 0; step < 5; ++step) {
    for (double y = 0.5; y < 1.5; y += 0.02) {
      for (double t = 0.0; t < 0.28; t += 0.02) cloud.emplace_back(1.0 + step * 0.28 + t, y, 0.17 * (step + 1));
    }
  }
  return cloud;
}

// `chunks` > 1 adds the cloud in that many slices (the map's voxel and block indices grow).
void checkAgainstBruteForce(const std::vector<Point>& cloud, double voxel_size, double max_distance,
                            unsigned seed, double extent, std::size_t chunks = 1) {
  VoxelHashMap map(voxel_size, cloud.size());  // no per-voxel cap: every point is kept
  for (std::size_t c = 0; c < chunks; ++c) {
    map.addPoints(std::vector<Point>(cloud.begin() + static_cast<long>(c * cloud.size() / chunks),
                                     cloud.begin() + static_cast<long>((c + 1) * cloud.size() / chunks)));
  }
  REQUIRE(map.size() == cloud.size());
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> coordinate(-0.5, extent + 0.5);
  std::uniform_real_distribution<double> offset(-max_distance, max_distance);
  std::uniform_int_distribution<std::size_t> pick(0, cloud.size() - 1);
  int found = 0;
  for (int q = 0; q < 500; ++q) {
    // Every other query lies near a cloud point, the rest anywhere around the cloud.
    const Point query = q % 2 == 0 ? Point(coordinate(generator), coordinate(generator), coordinate(generator))
                                   : Point(cloud[pick(generator)] + Point(offset(generator), offset(generator),
                                                                          offset(generator)));
    const auto expected = bruteNearest(cloud, query, max_distance);
    const auto neighbour = map.nearest(query, max_distance);
    CAPTURE(q);
    REQUIRE(neighbour.has_value() == expected.has_value());
    if (!expected) continue;
    ++found;
    CHECK(neighbour->distance == doctest::Approx(*expected).epsilon(1e-12));
    CHECK((neighbour->point - query).norm() == doctest::Approx(neighbour->distance).epsilon(1e-12));
    // within(): exactly the brute-force set.
    std::size_t inside = 0;
    for (const Point& point : cloud) inside += (point - query).norm() <= max_distance ? 1 : 0;
    CHECK(map.within(query, max_distance).size() == inside);
  }
  CHECK(found > 100);  // the queries exercised real hits, not only misses
}

}  // namespace

TEST_CASE("VoxelHashMap: nearest and within match brute force on random clouds") {
  const mlmap::Scan scan = mlmap::test::randomScan(3000, 7, 1.5);
  std::vector<Point> cloud = scan.points;
  for (Point& point : cloud) point += Point::Constant(1.5);  // [0, 3)³, crossing no key sign
  // Gates smaller than, equal to and several times the voxel size.
  checkAgainstBruteForce(cloud, 0.1, 0.05, 1, 3.0);
  checkAgainstBruteForce(cloud, 0.1, 0.1, 2, 3.0);
  checkAgainstBruteForce(cloud, 0.1, 0.35, 3, 3.0);
  checkAgainstBruteForce(scan.points, 0.25, 0.2, 4, 1.5);  // negative coordinates too
}

TEST_CASE("VoxelHashMap: nearest and within match brute force on a structured cloud") {
  const std::vector<Point> cloud = structuredCloud(5);
  checkAgainstBruteForce(cloud, 0.1, 0.08, 6, 3.0);
  checkAgainstBruteForce(cloud, 0.05, 0.3, 7, 3.0);
}

TEST_CASE("VoxelHashMap: gates of one to two voxels match brute force (own voxel and first shell first)") {
  // Searched voxel by voxel: the query's own voxel, then only the first shell where a point
  // within a voxel was found there, and nothing where no block meets the search's box.
  const std::vector<Point> cloud = structuredCloud(15);
  checkAgainstBruteForce(cloud, 0.1, 0.15, 16, 3.0);
  checkAgainstBruteForce(cloud, 0.1, 0.2, 17, 3.0, 2);
  const mlmap::Scan scan = mlmap::test::randomScan(600, 18, 2.0);  // sparse: many searches find nothing
  checkAgainstBruteForce(scan.points, 0.1, 0.12, 19, 2.0);
  checkAgainstBruteForce(scan.points, 0.1, 0.19, 20, 2.0, 3);
}

TEST_CASE("VoxelHashMap: wide gates (searched by blocks) match brute force, also after adding in parts") {
  // Gates of many voxels, as the wide ICP basin uses (up to 2 m at 0.1 m voxels): most queries
  // anywhere around the cloud then find a far point or, beyond the gate, none.
  const std::vector<Point> cloud = structuredCloud(8);
  checkAgainstBruteForce(cloud, 0.1, 1.5, 9, 3.0);
  checkAgainstBruteForce(cloud, 0.1, 0.45, 10, 3.0, 3);
  checkAgainstBruteForce(cloud, 0.05, 0.8, 11, 3.0, 5);
  const mlmap::Scan scan = mlmap::test::randomScan(400, 12, 2.0);  // sparse, across negative keys
  checkAgainstBruteForce(scan.points, 0.1, 2.0, 13, 2.0, 4);
  checkAgainstBruteForce(scan.points, 0.1, 0.25, 14, 2.0, 2);
}

TEST_CASE("VoxelHashMap: voxels keep at most max points, empty map finds nothing") {
  VoxelHashMap map(0.5, 3);
  CHECK_FALSE(map.nearest(Point::Zero(), 10.0).has_value());
  std::vector<Point> same(10, Point(0.1, 0.1, 0.1));
  same.emplace_back(2.0, 2.0, 2.0);
  map.addPoints(same);
  CHECK(map.size() == 4);
  CHECK(map.voxelCount() == 2);
  CHECK(map.points().size() == 4);
  CHECK_FALSE(map.nearest(Point(5, 5, 5), 1.0).has_value());
  CHECK_THROWS_AS(VoxelHashMap(0.0), mlmap::Error);
}

TEST_CASE("VoxelHashMap: normals of a plane, none on a line") {
  VoxelHashMap map(0.1);
  std::vector<Point> plane;
  for (double x = 0.0; x < 1.0; x += 0.02) {
    for (double y = 0.0; y < 1.0; y += 0.02) plane.emplace_back(x, y, 0.3 * x);
  }
  std::vector<Point> line;
  for (double x = 0.0; x < 1.0; x += 0.01) line.emplace_back(x, 5.0, 5.0);
  map.addPoints(plane);
  map.addPoints(line);
  map.estimateNormals();
  const Eigen::Vector3d expected = Eigen::Vector3d(-0.3, 0.0, 1.0).normalized();
  const auto on_plane = map.nearest(Point(0.5, 0.5, 0.15), 0.05);
  REQUIRE(on_plane);
  CHECK(std::abs(on_plane->normal.dot(expected)) == doctest::Approx(1.0).epsilon(1e-6));
  const auto on_line = map.nearest(Point(0.5, 5.0, 5.0), 0.05);
  REQUIRE(on_line);
  CHECK(on_line->normal.isZero());
}

TEST_CASE("VoxelHashMap: normals after adding points match a map built at once") {
  // A curved floor and a wall added in two halves: the voxels along the seam get new
  // neighbours from the second half, so their normals must be estimated again.
  std::vector<Point> first, second;
  for (double x = 0.0; x < 1.0; x += 0.02) {
    for (double y = 0.0; y < 1.0; y += 0.02) {
      (x < 0.5 ? first : second).emplace_back(x, y, 0.3 * x * x + 0.1 * y);  // curved: normals depend on the neighbourhood
      (y < 0.5 ? first : second).emplace_back(1.0, y, x);
    }
  }
  VoxelHashMap incremental(0.1, 1000);  // no cap: both maps keep every point
  incremental.addPoints(first);
  incremental.estimateNormals();
  incremental.addPoints(second);
  incremental.estimateNormals();
  std::vector<Point> all = first;
  all.insert(all.end(), second.begin(), second.end());
  VoxelHashMap at_once(0.1, 1000);
  at_once.addPoints(all);
  at_once.estimateNormals();
  REQUIRE(incremental.size() == at_once.size());
  int with_normal = 0;
  for (const Point& point : all) {
    const auto a = incremental.nearest(point, 0.01);
    const auto b = at_once.nearest(point, 0.01);
    REQUIRE(a);
    REQUIRE(b);
    CHECK((a->normal - b->normal).norm() < 1e-9);
    with_normal += a->normal.isZero() ? 0 : 1;
  }
  CHECK(with_normal > static_cast<int>(all.size()) * 8 / 10);
}

TEST_CASE("VoxelHashMap: a sparse plane gets normals from a grown neighbourhood, the same built at once or not") {
  // A far wall sampled as a scanner 20 m away samples it (points 0.2 m apart along its rows,
  // rows 0.4 m apart, 1 cm noise across): no 0.2 m neighbourhood holds six points off one row.
  std::vector<Point> first, second;
  std::uint32_t state = 12345;
  const auto noise = [&state] {
    state = state * 1664525u + 1013904223u;
    return (static_cast<double>(state >> 8) / 16777216.0 - 0.5) * 0.02;
  };
  for (double z = 0.0; z < 2.81; z += 0.4) {
    for (double y = 0.0; y < 2.21; y += 0.2) (y < 1.1 ? first : second).emplace_back(20.0 + noise(), y, z);
  }
  std::vector<Point> all = first;
  all.insert(all.end(), second.begin(), second.end());
  VoxelHashMap fixed(0.1);
  fixed.addPoints(all);
  fixed.estimateNormals();
  VoxelHashMap grown(0.1);
  grown.addPoints(all);
  grown.estimateNormals(mlmap::registration::NormalConfig{.max_radius = 0.8});
  VoxelHashMap incremental(0.1);
  incremental.addPoints(first);
  incremental.estimateNormals(mlmap::registration::NormalConfig{.max_radius = 0.8});
  incremental.addPoints(second);
  incremental.estimateNormals(mlmap::registration::NormalConfig{.max_radius = 0.8});
  int fixed_normals = 0, grown_facing = 0;
  for (const Point& point : all) {
    const auto a = fixed.nearest(point, 0.0);
    const auto b = grown.nearest(point, 0.0);
    const auto c = incremental.nearest(point, 0.0);
    REQUIRE(a);
    REQUIRE(b);
    REQUIRE(c);
    fixed_normals += a->normal.isZero() ? 0 : 1;
    grown_facing += std::abs(b->normal.x()) > 0.99 ? 1 : 0;
    CHECK((b->normal - c->normal).norm() < 1e-9);
  }
  CHECK(fixed_normals == 0);
  CHECK(grown_facing > static_cast<int>(all.size()) * 8 / 10);
}

TEST_CASE("VoxelHashMap: a grown neighbourhood gives the normal of that radius, to the bit") {
  // Two noisy planes sampled sparsely at random (~11 points per m², 1.5 m apart): at 0.1 m voxels
  // most neighbourhoods up to 0.2 m hold fewer than 6 points, so normals grow to 0.4 or 0.8 m
  // (whose voxels are found by blocks, not by a stencil lookup per offset). Each grown normal
  // must be, to the bit, that of a map estimated at the radius where it stopped growing: the
  // first of 0.1, 0.2, 0.4, 0.8 m that gives one (no corner within 0.8 m: no neighbourhood there
  // is dense enough yet not planar).
  std::mt19937 generator(21);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::uniform_real_distribution<double> along(0.0, 6.0), across(0.0, 4.0);
  std::vector<Point> cloud;
  for (int k = 0; k < 260; ++k) {
    const double a = along(generator), b = across(generator);
    cloud.emplace_back(a, b, 0.2 * a + noise(generator));
    cloud.emplace_back(-1.5 + noise(generator), a - 3.0, b);
  }
  VoxelHashMap grown(0.1);
  grown.addPoints(cloud);
  grown.estimateNormals({.radius = 0.1, .max_radius = 0.8});
  std::vector<VoxelHashMap> fixed;
  for (const double radius : {0.1, 0.2, 0.4, 0.8}) {
    fixed.emplace_back(0.1);
    fixed.back().addPoints(cloud);
    fixed.back().estimateNormals({.radius = radius});
  }
  std::array<int, 5> stopped{};  // at each radius, or never
  for (const Point& point : cloud) {
    const auto normal = grown.nearest(point, 0.0);
    REQUIRE(normal);
    std::size_t level = 0;
    while (level < fixed.size() && fixed[level].nearest(point, 0.0)->normal.isZero()) ++level;
    ++stopped[level];
    CHECK(normal->normal == (level < fixed.size() ? fixed[level].nearest(point, 0.0)->normal : Eigen::Vector3d::Zero()));
  }
  CAPTURE(stopped[0]);
  CAPTURE(stopped[4]);
  CHECK(stopped[2] > 50);  // both grown radii exercised
  CHECK(stopped[3] > 50);
}
