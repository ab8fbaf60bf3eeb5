// A block's point moments (beyond the paper): Welford and Chan agree with the plain
// sums, moving and turning them moves the points, and the ML map's rules keep them.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "mlmap/map/ml_map.hpp"
#include "mlmap/map/point_stats.hpp"

using namespace mlmap;

namespace {

// Mean and scatter of points, the plain way, in double.
void plainMoments(const std::vector<Eigen::Vector3d>& points, Eigen::Vector3d& mean, Eigen::Matrix3d& scatter) {
  mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) scatter += (p - mean) * (p - mean).transpose();
}

std::vector<Eigen::Vector3d> randomPoints(int count, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> across(-0.025, 0.025);
  std::normal_distribution<double> height(1.5, 0.8);
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < count; ++k) points.emplace_back(across(random), across(random), height(random));
  return points;
}

}  // namespace

TEST_CASE("PointStats: added one by one or merged in parts, the moments of the points") {
  const std::vector<Eigen::Vector3d> points = randomPoints(5000, 3);
  Eigen::Vector3d mean;
  Eigen::Matrix3d scatter;
  plainMoments(points, mean, scatter);
  PointStats whole;
  PointStats part_a;
  PointStats part_b;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const auto& p = points[k];
    whole.add(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    (k % 3 == 0 ? part_a : part_b).add(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  }
  part_a.merge(part_b);
  for (const PointStats* stats : {&whole, &part_a}) {
    CHECK(stats->count == points.size());
    CHECK((stats->mean() - mean).norm() < 1e-5);
    // Relative to the scatter's size (z spreads over metres, x and y over centimetres).
    CHECK((stats->scatterMatrix() - scatter).norm() < 1e-4 * scatter.norm());
    CHECK(std::abs(stats->scatter[0] - scatter(0, 0)) < 1e-3 * scatter(0, 0));
  }
}

TEST_CASE("PointStats: shifted and turned about z, the moments of the moved points") {
  const std::vector<Eigen::Vector3d> points = randomPoints(200, 4);
  PointStats stats;
  for (const auto& p : points) stats.add(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  const double yaw = 0.4;
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::vector<Eigen::Vector3d> moved;
  for (const auto& p : points) moved.push_back(rotation * p + Eigen::Vector3d(-0.01, 0.02, 0.3));
  Eigen::Vector3d mean;
  Eigen::Matrix3d scatter;
  plainMoments(moved, mean, scatter);
  const PointStats result = stats.turned(yaw, 0.3).shifted(0.01, -0.02);
  CHECK((result.mean() - mean).norm() < 1e-5);
  CHECK((result.scatterMatrix() - scatter).norm() < 1e-4 * scatter.norm());
}

TEST_CASE("PointStats: the map's blocks hold their points' mean across the cell and their count") {
  MLMap map(0.1);
  // A wall at x = 1.237 (a cell spans [1.2, 1.3)), seen from 0 to 2 m, and a floor cell.
  for (int k = 0; k <= 200; ++k) map.insert({1.237, 0.55, 0.01 * k}, 1e-4);
  for (int a = 0; a < 10; ++a) {
    for (int b = 0; b < 10; ++b) map.insert({0.305 + 0.01 * a, 0.405 + 0.01 * b, 0.0}, 1e-4);
  }
  const auto wall = map.blocks(map.cellOf(1.237, 0.55));
  REQUIRE(wall.size() == 1);
  CHECK(wall[0].isVertical());
  CHECK(wall[0].points.count == 201);
  CHECK(wall[0].points.mean_x == doctest::Approx(1.237 - 1.25).epsilon(1e-4));
  CHECK(wall[0].points.mean_z == doctest::Approx(1.0).epsilon(1e-5));
  const auto floor = map.blocks(map.cellOf(0.35, 0.45));
  REQUIRE(floor.size() == 1);
  CHECK(floor[0].points.count == 100);
  CHECK(std::abs(floor[0].points.mean_x) < 1e-6);
  CHECK(std::abs(floor[0].points.mean_y) < 1e-6);
  // The scatter across: ten columns 1 cm apart, ten points each.
  CHECK(floor[0].points.scatter[0] == doctest::Approx(100 * 0.000825).epsilon(1e-3));
}
