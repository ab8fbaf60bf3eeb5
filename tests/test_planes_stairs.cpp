// A staircase whose noise the map does not know (issue 19): plane_seg's ANYmal stair map
// (2 cm elevation grid, 16.5 cm risers on 26 cm treads, 1 cm noise) read from a file
// is fused with the 3 cm σ assumed for points without one; ε from it (9 cm) is more
// than half a riser, every tread candidate refitted into a ramp through two treads,
// and at 5 cm cells no tread was a patch.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

#include "mlmap/planes/ermsm.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

constexpr double kFileVariance = 0.03 * 0.03;  // what the CLI assumes for points without one
constexpr double kRiser = 0.165;
constexpr double kTread = 0.26;
constexpr double kEdge = 0.04;  // the elevation grid smooths each riser over this much of x
constexpr double kStart = 0.03;  // the first riser's foot: off the cell boundaries
constexpr int kTreads = 3;

double tiltDeg(const Eigen::Vector3d& normal) {
  return std::acos(std::min(1.0, std::abs(normal.normalized().z()))) * 180.0 / std::numbers::pi;
}

// A lower landing, `treads` treads and an upper landing, 2 m wide, sampled every 2 cm
// with `noise`; each riser a steep slope of the grid's smoothing, the first at `start`.
struct Staircase {
  double cell = 0.05;   // m
  double noise = 0.005; // m
  double start = kStart;
  int treads = kTreads;
};

test::PlaneSceneBuilder elevationStairs(const Staircase& stairs, unsigned seed) {
  test::PlaneSceneBuilder scene(stairs.cell, stairs.noise, seed);
  scene.withNoise(stairs.noise, kFileVariance).floor(-1.5, 0.0, stairs.start, 2.0, 0.0);
  for (int step = 0; step <= stairs.treads; ++step) {
    const double foot = stairs.start + step * (kEdge + kTread);
    scene.rectangle({foot, 0.0, step * kRiser}, {kEdge, 0.0, kRiser}, {0.0, 2.0, 0.0}, 0.02);
    const double depth = step < stairs.treads ? kTread : 1.5;  // the upper landing after the last
    scene.floor(foot + kEdge, 0.0, foot + kEdge + depth, 2.0, (step + 1) * kRiser);
  }
  return scene;
}

// The largest patch whose centroid lies within 4 cm of `height`, or null.
const Plane* largestAt(const PlaneDetection& detection, double height) {
  const Plane* largest = nullptr;
  for (const Plane& plane : detection.planes) {
    if (std::abs(plane.centroid.z() - height) > 0.04) continue;
    if (largest == nullptr || plane.area > largest->area) largest = &plane;
  }
  return largest;
}

// No patch of over 0.2 m² leans through the treads: each within 8° of level or steeper
// than 60° (a riser).
void checkNoRamp(const PlaneDetection& detection) {
  for (const Plane& plane : detection.planes) {
    CAPTURE(plane.normal.transpose());
    CAPTURE(plane.centroid.transpose());
    if (plane.area > 0.2) CHECK((tiltDeg(plane.normal) < 8.0 || tiltDeg(plane.normal) > 60.0));
  }
}

}  // namespace

TEST_CASE("Planes on stairs: each tread of an elevation map read from a file is its own level patch at 5 cm cells") {
  for (const unsigned seed : {1U, 2U}) {
    CAPTURE(seed);
    test::PlaneSceneBuilder scene = elevationStairs(Staircase{}, seed);
    const PlaneDetection detection = detectPlanes(scene.map());
    for (int step = 1; step <= kTreads; ++step) {
      CAPTURE(step);
      const double height = step * kRiser;
      const Plane* tread = largestAt(detection, height);
      REQUIRE(tread != nullptr);
      // Level within 8° (the riser edges beside it pull 3-5.5°), not a ramp (29° from
      // tread to tread), at the tread's height.
      CHECK(tiltDeg(tread->normal) < 8.0);
      CHECK(std::abs(tread->centroid.z() - height) < 0.015);
      // Most of the tread's 0.52 m²; it reaches neither neighbour (0.6 m² and more).
      CHECK(tread->area > 0.35);
      CHECK(tread->area < 0.6);
    }
    checkNoRamp(detection);
  }
}

TEST_CASE("Planes on stairs: at 10 cm cells each tread is its own step patch, not part of a ramp") {
  // Five treads at 10 cm cells: a tread is 2.6 cells deep, and its front and back cells
  // hold the risers' points below their tops. Fitted to all of its blocks' points, each
  // tread leaned 17-21° towards its risers, and the coplanar merge chained them into one
  // ramp tilted 28° over all five.
  constexpr int kFiveTreads = 5;
  constexpr double kOffGrid = 0.08;  // the first riser's foot, m
  for (const unsigned seed : {1U, 2U}) {
    CAPTURE(seed);
    test::PlaneSceneBuilder scene =
        elevationStairs(Staircase{.cell = 0.1, .noise = 0.01, .start = kOffGrid, .treads = kFiveTreads}, seed);
    const PlaneDetection detection = detectPlanes(scene.map());
    for (int step = 1; step <= kFiveTreads; ++step) {
      CAPTURE(step);
      const Plane* tread = largestAt(detection, step * kRiser);
      REQUIRE(tread != nullptr);
      // Within 8° of level (its edge blocks lean it 6-7°), most of its 0.52 m² and no
      // neighbour's.
      CHECK(tiltDeg(tread->normal) < 8.0);
      CHECK(tread->area > 0.35);
      CHECK(tread->area < 0.7);
    }
    checkNoRamp(detection);
  }
}
