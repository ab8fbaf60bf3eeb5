// Voxel down-sampling and range cropping against direct computations.
#include <doctest/doctest.h>

#include "helpers.hpp"
#include "mlmap/registration/preprocessing.hpp"

using mlmap::Point;
using namespace mlmap::registration;

TEST_CASE("voxelDownSample: one centroid per voxel, in first-seen order") {
  const std::vector<Point> points = {{0.01, 0.01, 0.01}, {0.5, 0.5, 0.5}, {0.03, 0.05, 0.07},
                                     {-0.01, 0.0, 0.0},  {0.58, 0.53, 0.52}};
  const std::vector<Point> sampled = voxelDownSample(points, 0.1);
  REQUIRE(sampled.size() == 3);
  CHECK(sampled[0].isApprox(Point(0.02, 0.03, 0.04)));
  CHECK(sampled[1].isApprox(Point(0.54, 0.515, 0.51)));
  CHECK(sampled[2].isApprox(Point(-0.01, 0.0, 0.0)));
  CHECK(voxelDownSample({}, 0.1).empty());
  CHECK_THROWS_AS(voxelDownSample(points, 0.0), mlmap::Error);
}

TEST_CASE("voxelDownSample: random cloud keeps one point per occupied voxel") {
  const mlmap::Scan scan = mlmap::test::randomScan(5000, 3, 1.0);
  const std::vector<Point> sampled = voxelDownSample(scan.points, 0.5);
  CHECK(sampled.size() <= 64);  // 4 × 4 × 4 voxels span [-1, 1)³
  CHECK(sampled.size() >= 60);
  for (const Point& point : sampled) CHECK(point.cwiseAbs().maxCoeff() < 1.0);
}

TEST_CASE("cropRange keeps points within the range interval") {
  const std::vector<Point> points = {{0.01, 0, 0}, {1, 0, 0}, {0, 3, 4}, {10, 0, 0}};
  const std::vector<Point> kept = cropRange(points, 0.5, 5.0);
  REQUIRE(kept.size() == 2);
  CHECK(kept[1].isApprox(Point(0, 3, 4)));
}
