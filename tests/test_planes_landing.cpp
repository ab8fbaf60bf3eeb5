// A flight from the floor that ends on a landing (issue 19: classes relative to the floor
// found; plane_seg's ANYmal stairs, whose upper landing, 3.4 m² over 0.6-0.75 m² treads,
// read 'step'): the landing is floor at its own height, a patch of its own, and the floor
// below stays at the floor's height.
#include <doctest/doctest.h>

#include <cmath>

#include "mlmap/planes/ermsm.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

// The patch whose centroid lies nearest `at`.
const Plane* nearest(const PlaneDetection& detection, const Eigen::Vector3d& at) {
  const Plane* found = nullptr;
  for (const Plane& plane : detection.planes)
    if (found == nullptr || (plane.centroid - at).norm() < (found->centroid - at).norm()) found = &plane;
  return found;
}

}  // namespace

TEST_CASE("Classes: the landing a flight from the floor climbs to is floor, apart from the floor below") {
  const double rise = 0.17, run = 0.28, width = 1.5, start = 3.013;
  const int steps = 4;
  // At 5 cm cells; at 10 cm the second tread (0.28 m, under three cells) comes as no level
  // patch, the flight from the floor stops at the first, and the treads above and the
  // landing read 'table' (the README's weak spot on flights at 10 cm cells).
  for (const double cell : {0.05}) {
    CAPTURE(cell);
    test::PlaneSceneBuilder scene(cell, 0.005, 3);
    scene.withNoise(0.005, 2.5e-5).floor(0.0, 0.0, start, width, 0.0);
    for (int k = 0; k < steps; ++k) {
      const double front = start + k * run;
      scene.floor(front, 0.0, front + run, width, (k + 1) * rise);  // tread
      scene.wallX(front, 0.0, width, k * rise, (k + 1) * rise);      // riser
    }
    const double top = start + steps * run;
    scene.floor(top, 0.0, top + 2.0, width, (steps + 1) * rise);  // the landing, 3 m²
    scene.wallX(top, 0.0, width, steps * rise, (steps + 1) * rise);
    const PlaneDetection detection = detectPlanes(scene.map());

    const Plane* floor = nearest(detection, {start / 2.0, width / 2.0, 0.0});
    const Plane* landing = nearest(detection, {top + 1.0, width / 2.0, (steps + 1) * rise});
    REQUIRE(floor != nullptr);
    REQUIRE(landing != floor);
    CHECK(floor->label == PlaneClass::Floor);
    CHECK(std::abs(floor->centroid.z()) < 0.02);  // not merged with the landing
    CHECK(landing->label == PlaneClass::Floor);   // 'step' before
    CHECK(std::abs(landing->centroid.z() - (steps + 1) * rise) < 0.02);
    CHECK(landing->area > 2.0);
    for (int k = 1; k < steps; ++k) {  // the treads between stay steps
      const Plane* tread = nearest(detection, {start + (k + 0.5) * run, width / 2.0, (k + 1) * rise});
      CHECK(tread->label == PlaneClass::Step);
    }
  }
}
