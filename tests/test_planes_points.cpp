// Planes where the points are, not where the cells are (issue 19): walls turned to the
// grid, walls on cell boundaries, and the RMS a user reads as the fit.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mlmap/planes/ermsm.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * 180.0 / std::numbers::pi;
}

// The patches whose normal lies within 3° of `normal`.
std::vector<const Plane*> planesAlong(const PlaneDetection& detection, const Eigen::Vector3d& normal) {
  std::vector<const Plane*> found;
  for (const Plane& plane : detection.planes) {
    if (angleDeg(plane.normal, normal) < 3.0) found.push_back(&plane);
  }
  return found;
}

}  // namespace

TEST_CASE("Planes on points: a room turned 5 to 10 degrees to the grid keeps its four walls, one patch each") {
  for (const double degrees : {5.0, 7.0, 10.0}) {
    CAPTURE(degrees);
    const double yaw = degrees * std::numbers::pi / 180.0;
    const Eigen::Vector3d along(std::cos(yaw), std::sin(yaw), 0.0);
    const Eigen::Vector3d across(-std::sin(yaw), std::cos(yaw), 0.0);
    const Eigen::Vector3d up(0.0, 0.0, 2.4);
    const Eigen::Vector3d origin(0.3, 0.2, 0.0);
    const double length = 4.0;
    const double width = 3.0;
    test::PlaneSceneBuilder scene(0.05, 0.005, 7);
    scene.rectangle(origin, along * length, across * width)
        .rectangle(origin, along * length, up)
        .rectangle(origin + across * width, along * length, up)
        .rectangle(origin, across * width, up)
        .rectangle(origin + along * length, across * width, up);
    const PlaneDetection detection = detectPlanes(scene.map());
    for (const Eigen::Vector3d& normal : {across, along}) {
      const auto walls = planesAlong(detection, normal);
      // Two walls of each orientation, each one patch.
      CHECK(walls.size() == 2);
      for (const Plane* wall : walls) {
        CHECK(angleDeg(wall->normal, normal) < 1.0);
        const double expected_area = (normal == across ? length : width) * up.norm();
        CHECK(wall->area == doctest::Approx(expected_area).epsilon(0.15));
      }
    }
  }
}

TEST_CASE("Planes on points: a wall on a cell boundary has its own offset, area and the points' RMS") {
  const double noise = 0.005;
  test::PlaneSceneBuilder scene(0.05, noise, 3);
  scene.wallX(1.0, 0.0, 3.0, 0.0, 2.5);  // x = 1.0: the boundary of two cell columns
  const PlaneDetection detection = detectPlanes(scene.map());
  REQUIRE(detection.planes.size() == 1);
  const Plane& wall = detection.planes[0];
  CHECK(angleDeg(wall.normal, Eigen::Vector3d::UnitX()) < 0.5);
  CHECK(std::abs(std::abs(wall.offset) - 1.0) < 0.002);
  // Both cell columns hold half the wall's points: the area is the wall's, not twice it.
  CHECK(wall.area == doctest::Approx(3.0 * 2.5).epsilon(0.1));
  // The RMS is the points' distance to the plane: the noise, not half a cell.
  CHECK(wall.rms == doctest::Approx(noise).epsilon(0.3));
}

TEST_CASE("Planes on points: a floor's offset and RMS are its points' own") {
  const double noise = 0.004;
  test::PlaneSceneBuilder scene(0.1, noise, 5);
  scene.floor(0.0, 0.0, 3.0, 3.0, 0.123);
  const PlaneDetection detection = detectPlanes(scene.map());
  REQUIRE(detection.planes.size() == 1);
  CHECK(std::abs(std::abs(detection.planes[0].offset) - 0.123) < 0.001);
  CHECK(detection.planes[0].rms == doctest::Approx(noise).epsilon(0.3));
}
