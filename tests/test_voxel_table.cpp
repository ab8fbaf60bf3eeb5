// VoxelTable against std::map: indices in insertion order, lookups of present and absent
// keys across rehashes, negative and far coordinates; voxelKeyOf against std::floor.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include "mlmap/registration/voxel_table.hpp"

using mlmap::Point;
using mlmap::registration::VoxelKey;
using mlmap::registration::VoxelTable;
using mlmap::registration::voxelKeyOf;

TEST_CASE("VoxelTable: insert and find match std::map, indices in insertion order") {
  std::mt19937 generator(3);
  std::uniform_int_distribution<std::int32_t> near(-40, 40);
  std::uniform_int_distribution<std::int32_t> far(-2000000000, 2000000000);
  VoxelTable table;
  std::map<std::tuple<std::int32_t, std::int32_t, std::int32_t>, std::uint32_t> reference;
  for (int n = 0; n < 20000; ++n) {  // many rehashes from the empty table
    const bool is_far = n % 10 == 0;
    const VoxelKey key = is_far ? VoxelKey{far(generator), far(generator), far(generator)}
                                : VoxelKey{near(generator), near(generator), near(generator)};
    const auto [index, inserted] = table.insert(key);
    const auto [it, reference_inserted] =
        reference.try_emplace({key.x, key.y, key.z}, static_cast<std::uint32_t>(reference.size()));
    REQUIRE(inserted == reference_inserted);
    REQUIRE(index == it->second);
    REQUIRE(table.key(index) == key);
  }
  CHECK(table.size() == reference.size());
  for (const auto& [key, index] : reference) {
    CHECK(table.find({std::get<0>(key), std::get<1>(key), std::get<2>(key)}) == index);
  }
  int absent = 0;
  for (int n = 0; n < 2000; ++n) {
    const VoxelKey key{near(generator) + 100, near(generator), near(generator)};
    if (reference.count({key.x, key.y, key.z}) == 0) {
      CHECK(table.find(key) == VoxelTable::kMissing);
      ++absent;
    }
  }
  CHECK(absent > 1000);
  CHECK(VoxelTable().find({0, 0, 0}) == VoxelTable::kMissing);
}

TEST_CASE("voxelKeyOf: floor of the scaled coordinates, clamped far away") {
  std::mt19937 generator(5);
  std::uniform_real_distribution<double> coordinate(-50.0, 50.0);
  for (int n = 0; n < 10000; ++n) {
    const Point point(coordinate(generator), coordinate(generator), coordinate(generator));
    const VoxelKey key = voxelKeyOf(point, 1.0 / 0.05);
    CHECK(key.x == static_cast<std::int32_t>(std::floor(point.x() * 20.0)));
    CHECK(key.y == static_cast<std::int32_t>(std::floor(point.y() * 20.0)));
    CHECK(key.z == static_cast<std::int32_t>(std::floor(point.z() * 20.0)));
  }
  CHECK(voxelKeyOf(Point(-0.0, 0.0, -1e-300), 10.0) == VoxelKey{0, 0, -1});
  CHECK(voxelKeyOf(Point(-1.0, 1.0, -0.1), 10.0) == VoxelKey{-10, 10, -1});
  const VoxelKey huge = voxelKeyOf(Point(1e300, -1e300, 0.0), 10.0);
  CHECK(huge.x == 2000000000);
  CHECK(huge.y == -2000000000);
}
