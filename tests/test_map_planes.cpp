// map/map_planes.hpp: eRMSM on a Map keeps the planes with it and labels its blocks,
// as detectPlanes on its blocks and setPlanes do.
#include <doctest/doctest.h>

#include "mlmap/map/map_planes.hpp"

using namespace mlmap;

TEST_CASE("Map planes: detectPlanes on a Map keeps its planes and labels its blocks") {
  MapConfig config;
  config.cell_size = 0.1;
  config.with_octree = false;
  Map map(config), copy(config);
  Scan scan;
  for (int i = 0; i < 60; ++i) {
    for (int j = 0; j < 40; ++j) {
      scan.points.emplace_back(0.05 * i, 0.05 * j, 0.0);           // floor, 3 × 2 m
      scan.points.emplace_back(0.05 * i, 0.0, 0.05 * j + 0.05);   // wall, 3 × 2 m
    }
  }
  map.insertScan(scan);
  copy.insertScan(scan);
  const PlaneDetection& detection = detectPlanes(map);
  REQUIRE(map.planes().has_value());
  CHECK(&detection == &*map.planes());
  const PlaneDetection reference = detectPlanes(copy.blocks());
  CHECK(detection.planes.size() == reference.planes.size());
  CHECK(detection.planes.size() >= 2);
  CHECK(detection.stats.labelled_blocks == reference.stats.labelled_blocks);
  CHECK(detection.stats.labelled_blocks > 0);
}
