// A wall the direction-spread rule leaves out is said (issue 19: no silent garbage). In a
// dense cloud whose range noise is a good part of a cell (3 cm at 0.1 m cells, the
// UTM-30LX's specified ±30 mm) the noise tails fill the next cell columns with blocks of a
// few points beside the wall's, the windows' lines through them turn with the cells, and
// the walls' directions spread past 8°: make_scene.py's room turned 7° lost three of its
// four walls (README, weak spots) until session 45, when a wall's worth of blocks became
// excused by their directions' noise. ErmsmStats keeps the largest refusal (a curved wall's
// facets) and `mlmap planes` prints a note.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

#include "mlmap/planes/ermsm.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

// A 6 x 5 x 2.5 m room turned `turn_deg` about z, its walls sampled every 1.5 cm, floor and
// ceiling every 3 cm, with `noise` m of noise across each.
test::PlaneSceneBuilder turnedRoom(double turn_deg, double noise) {
  const double a = turn_deg * std::numbers::pi / 180.0;
  const Eigen::Vector3d x(std::cos(a), std::sin(a), 0.0), y(-std::sin(a), std::cos(a), 0.0), z(0.0, 0.0, 2.5);
  const Eigen::Vector3d origin(0.013, 0.027, 0.0);
  test::PlaneSceneBuilder scene(0.1, noise, 1);
  scene.withNoise(noise, 0.03 * 0.03)
      .rectangle(origin, 6.0 * x, 5.0 * y, 0.03)
      .rectangle(origin + z, 6.0 * x, 5.0 * y, 0.03)
      .rectangle(origin, 6.0 * x, z, 0.015)
      .rectangle(origin + 5.0 * y, 6.0 * x, z, 0.015)
      .rectangle(origin, 5.0 * y, z, 0.015)
      .rectangle(origin + 6.0 * x, 5.0 * y, z, 0.015);
  return scene;
}

std::size_t wallCount(const PlaneDetection& detection) {
  std::size_t walls = 0;
  for (const Plane& plane : detection.planes) walls += plane.label == PlaneClass::Wall && plane.area > 5.0 ? 1 : 0;
  return walls;
}

}  // namespace

TEST_CASE("Refused walls: a dense room with 3 cm of noise at 0.1 m cells keeps its four walls") {
  // Before session 45 one of the four was refused (28.8 m² at 8.2°): a wall's blocks are
  // now excused by their directions' noise as level planes are, where they cover a wall's worth.
  test::PlaneSceneBuilder scene = turnedRoom(7.0, 0.03);
  const PlaneDetection detection = detectPlanes(scene.map());
  MESSAGE("walls " << wallCount(detection) << ", refused " << detection.stats.refused_wall_area << " m², spread "
                   << detection.stats.refused_wall_spread_deg << " deg");
  CHECK(wallCount(detection) == 4);
  CHECK(detection.stats.refused_wall_area < 10.0);
}

TEST_CASE("Refused walls: a curved wall with little noise stays refused, and is said") {
  // Half a cylinder of radius 3 m, 2.5 m high, on a floor, 5 mm of noise: its facets' blocks
  // cover more than a wall's worth each, but their directions fan out by the curvature, not
  // by noise, so the excuse for noise does not apply.
  constexpr double kRadius = 3.0;
  test::PlaneSceneBuilder scene(0.1, 0.005, 1);
  scene.withNoise(0.005, 0.03 * 0.03)
      .rectangle({-kRadius - 1.0, -1.0, 0.0}, {2.0 * kRadius + 2.0, 0.0, 0.0}, {0.0, kRadius + 2.0, 0.0}, 0.03);
  constexpr int kStrips = 300;
  for (int k = 0; k < kStrips; ++k) {
    const double a0 = std::numbers::pi * k / kStrips, a1 = std::numbers::pi * (k + 1) / kStrips;
    const Eigen::Vector3d from(kRadius * std::cos(a0), kRadius * std::sin(a0), 0.0);
    const Eigen::Vector3d to(kRadius * std::cos(a1), kRadius * std::sin(a1), 0.0);
    scene.rectangle(from, to - from, {0.0, 0.0, 2.5}, 0.015);
  }
  const PlaneDetection detection = detectPlanes(scene.map());
  MESSAGE("walls " << wallCount(detection) << ", refused " << detection.stats.refused_wall_area << " m², spread "
                   << detection.stats.refused_wall_spread_deg << " deg");
  CHECK(wallCount(detection) == 0);
  CHECK(detection.stats.refused_wall_area > 5.0);
  CHECK(detection.stats.refused_wall_spread_deg > 8.0);
}

TEST_CASE("Refused walls: with 5 mm of noise every wall is found and nothing wall-sized is refused") {
  test::PlaneSceneBuilder scene = turnedRoom(7.0, 0.005);
  const PlaneDetection detection = detectPlanes(scene.map());
  MESSAGE("walls " << wallCount(detection) << ", refused " << detection.stats.refused_wall_area << " m²");
  CHECK(wallCount(detection) == 4);
  CHECK(detection.stats.refused_wall_area < 10.0);
}
