// Parallel faces a few cm apart (issue 19: "a candidate does not absorb a parallel layer
// a few cm away"). OctoMap's fr079 has walls whose lower face (to 0.56 m) stands 8-10 cm
// in front of the upper one (from 0.62-0.71 m); at ε = 5 cm a plane between the faces
// matched both, and one tilted patch took them, the upper face's points 4 cm off it.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

#include "mlmap/planes/ermsm.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * 180.0 / std::numbers::pi;
}

// Walls facing y, largest first.
std::vector<const Plane*> wallsFacingY(const PlaneDetection& detection) {
  std::vector<const Plane*> walls;
  for (const Plane& plane : detection.planes) {
    if (angleDeg(plane.normal, Eigen::Vector3d::UnitY()) < 10.0) walls.push_back(&plane);
  }
  return walls;
}

}  // namespace

TEST_CASE("Planes in layers: a wall's lower face 8 cm in front of its upper face is two patches") {
  // At 5 cm cells; at 10 cm the row of cells the lower face's points reach holds the
  // upper face too, and its blocks mix both.
  for (const unsigned seed : {3U, 4U}) {
    CAPTURE(seed);
    const double cell = 0.05;
    // 5 mm noise, as the build is told: σ known, no measurement needed. (With 1 cm the
    // tails of the upper face put blocks of a few points into the lower face's cells,
    // half way between the faces, and those link them: a limit of the sheets.)
    test::PlaneSceneBuilder scene(cell, 0.005, seed);
    scene.withNoise(0.005, 0.25e-4)
        .floor(0.0, -2.0, 4.0, 0.0, 0.0)
        .wallY(0.0, 0.0, 4.0, 0.0, 0.55)
        .wallY(0.08, 0.0, 4.0, 0.65, 2.2);
    ErmsmConfig config;
    config.noise = 0.005;
    const PlaneDetection detection = detectPlanes(scene.map(), config);
    const auto walls = wallsFacingY(detection);
    REQUIRE(walls.size() >= 2);
    const Plane* lower = nullptr;
    const Plane* upper = nullptr;
    for (const Plane* wall : walls) {
      if (wall->centroid.z() < 0.58 && lower == nullptr) lower = wall;
      if (wall->centroid.z() > 0.58 && upper == nullptr) upper = wall;
    }
    REQUIRE(lower != nullptr);
    REQUIRE(upper != nullptr);
    // Each on its own face: y = 0 and y = 0.08, upright, its points within the noise.
    CHECK(std::abs(lower->offset) < 0.01);
    CHECK(std::abs(std::abs(upper->offset) - 0.08) < 0.01);
    CHECK(angleDeg(lower->normal, Eigen::Vector3d::UnitY()) < 2.0);
    CHECK(angleDeg(upper->normal, Eigen::Vector3d::UnitY()) < 2.0);
    CHECK(lower->rms < 0.015);
    CHECK(upper->rms < 0.015);
    CHECK(upper->area == doctest::Approx(4.0 * 1.55).epsilon(0.15));
  }
}

TEST_CASE("Planes in layers: at 10 cm cells two faces found apart are not merged back into one") {
  // OctoMap's fr079 at 10 cm cells: each of two faces 7 cm apart was found on its own
  // (0.7 and 1.0 cm RMS) and then merged as coplanar pieces into one patch, 3.5 cm RMS.
  // Here faces 12 cm apart with 1 cm of noise, in two of the layouts where that happened
  // (in others the sheets keep them apart, or, where the cells mix both faces, one patch
  // takes both from the start: a limit at this cell size).
  struct Layout {
    double top;  // m, the lower face's top; the upper face starts 10 cm above it
    unsigned seed;
  };
  for (const Layout layout : {Layout{0.55, 3U}, Layout{0.95, 4U}}) {
    CAPTURE(layout.top);
    CAPTURE(layout.seed);
    test::PlaneSceneBuilder scene(0.1, 0.01, layout.seed);
    scene.withNoise(0.01, 1e-4)
        .floor(0.0, -2.0, 4.0, 0.0, 0.0)
        .wallY(0.0, 0.0, 4.0, 0.0, layout.top)
        .wallY(0.12, 0.0, 4.0, layout.top + 0.1, 2.2);
    const PlaneDetection detection = detectPlanes(scene.map());
    const auto walls = wallsFacingY(detection);
    REQUIRE(!walls.empty());
    // The largest is the upper face, on its own plane and within its noise.
    CHECK(std::abs(std::abs(walls[0]->offset) - 0.12) < 0.01);
    CHECK(walls[0]->rms < 0.015);
    CHECK(walls[0]->centroid.z() > layout.top);
    // The lower face is a patch of its own, at most a few cm off its plane (the floor's
    // edge cells pull it).
    bool lower_found = false;
    for (const Plane* wall : walls) {
      if (wall->centroid.z() < layout.top && std::abs(wall->offset) < 0.04) lower_found = true;
    }
    CHECK(lower_found);
  }
}

TEST_CASE("Planes in layers: a wall's noise tail beyond a cell boundary is no plane of its own") {
  // The simulated lab at 2 cm cells: each wall on a cell boundary came with one or two
  // planes 2.3-2.6 cm either side of it (0.3 cm RMS against the wall's 0.8 cm), made of the
  // blocks that hold only its points' tail in the next cell column out. Here two such walls
  // with 1 cm of noise, densely sampled, and a floor and ceiling with 4 mm (the walls seen
  // head on, the level surfaces grazing): σ reads 4.4 mm, ε 2 cm, and before this rule both
  // seeds gave a plane 2.4 cm off a wall with 0.33-0.37 cm RMS.
  for (const unsigned seed : {1U, 2U}) {
    CAPTURE(seed);
    test::PlaneSceneBuilder scene(0.02, 0.004, seed);
    scene.withNoise(0.004, 1.6e-5).floor(0.0, 0.0, 4.0, 4.0, 0.0).floor(0.0, 0.0, 4.0, 4.0, 1.5);
    scene.withNoise(0.01, 1e-4)
        .rectangle({0.0, 0.0, 0.0}, {3.0, 0.0, 0.0}, {0.0, 0.0, 1.5}, 0.005)
        .rectangle({0.0, 0.0, 0.0}, {0.0, 3.0, 0.0}, {0.0, 0.0, 1.5}, 0.005);
    const PlaneDetection detection = detectPlanes(scene.map());
    int walls = 0;
    int tails = 0;
    for (const Plane& plane : detection.planes) {
      const bool along_wall = angleDeg(plane.normal, Eigen::Vector3d::UnitX()) < 2.0 ||
                              angleDeg(plane.normal, Eigen::Vector3d::UnitY()) < 2.0;
      if (!along_wall) continue;
      if (std::abs(plane.offset) < 0.01 && plane.block_count > 500) ++walls;
      if (std::abs(plane.offset) > 0.015 && std::abs(plane.offset) < 0.035) ++tails;
    }
    CHECK(walls == 2);
    CHECK(tails == 0);
  }
}
