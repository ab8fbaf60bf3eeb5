// The walls' dominant direction, folded to a quarter turn: the turn between two clouds of
// the same room, the start merge --register takes when the frames differ by up to 30 deg.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "mlmap/registration/wall_yaw.hpp"

using namespace mlmap::registration;

namespace {

// Points on the four walls and the floor of a 6 x 4 x 3 m room, every 5 cm, turned by `yaw`.
std::vector<mlmap::Point> roomPoints(double yaw_deg) {
  std::vector<mlmap::Point> points;
  for (double z = 0.0; z <= 3.0; z += 0.05) {
    for (double x = 0.0; x <= 6.0; x += 0.05) {
      points.emplace_back(x, 0.0, z);
      points.emplace_back(x, 4.0, z);
    }
    for (double y = 0.0; y <= 4.0; y += 0.05) {
      points.emplace_back(0.0, y, z);
      points.emplace_back(6.0, y, z);
    }
  }
  for (double x = 0.0; x <= 6.0; x += 0.1) {
    for (double y = 0.0; y <= 4.0; y += 0.1) points.emplace_back(x, y, 0.0);
  }
  const Eigen::AngleAxisd turn(yaw_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ());
  for (mlmap::Point& point : points) point = turn * point;
  return points;
}

WallYaw wallsOf(const std::vector<mlmap::Point>& points) {
  VoxelHashMap map(0.1);
  map.addPoints(points);
  map.estimateNormals();
  return wallYaw(map, points);
}

double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }

}  // namespace

TEST_CASE("WallYaw: the turn between two clouds of a room, modulo a quarter turn") {
  const WallYaw base = wallsOf(roomPoints(0.0));
  CHECK(base.strength > 0.9);
  CHECK(std::abs(degrees(base.yaw)) < 0.5);
  for (const double yaw : {-28.0, -22.0, 7.0, 29.0, 40.0}) {
    CAPTURE(yaw);
    const WallYaw turned = wallsOf(roomPoints(yaw));
    CHECK(turned.strength > 0.9);
    // other -> base: the turn that brings the turned room's walls onto the base's.
    CHECK(std::abs(degrees(foldedTurn(turned, base)) + yaw) < 0.5);
  }
  // 60 deg is -30 deg modulo a quarter turn: beyond ±45 deg the fold cannot tell.
  CHECK(std::abs(degrees(foldedTurn(wallsOf(roomPoints(60.0)), base)) - 30.0) < 0.5);
}

TEST_CASE("WallYaw: walls in every direction have no dominant one") {
  // A round room (a cylinder wall): its normals point every way.
  std::vector<mlmap::Point> points;
  for (double z = 0.0; z <= 3.0; z += 0.05) {
    for (double a = 0.0; a < 2.0 * std::numbers::pi; a += 0.01) points.emplace_back(4.0 * std::cos(a), 4.0 * std::sin(a), z);
  }
  const WallYaw round = wallsOf(points);
  CHECK(round.walls > 1000);
  CHECK(round.strength < 0.1);
}
