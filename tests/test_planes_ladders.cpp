// A wall seen as a few horizontal scan lines (issue 19: Bobkov's room 2, walls above a
// sideboard; the PCL room scans' far walls): where the lines lie further apart than the
// stack gap, each cell column holds a ladder of short level blocks, one per line. A ladder
// of at least ErmsmConfig::ladder_blocks rungs is one wall block. With six rungs asked, a
// strip four or five lines tall (0.4-0.5 m of wall between furniture and the cloud's top,
// or a tilting laser's 1° lines 7 m away) was rungs only: at 12 cm between lines no wall
// patch at 5 or 10 cm cells.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "mlmap/planes/ermsm.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

TEST_CASE("eRMSM: a wall strip seen as four or five scan lines 12 cm apart is a wall patch") {
  for (const double cell : {0.05, 0.1}) {
    for (const int lines : {4, 5}) {
      for (const unsigned seed : {1U, 2U}) {
        CAPTURE(cell);
        CAPTURE(lines);
        CAPTURE(seed);
        test::PlaneSceneBuilder scene(cell, 0.01, seed);
        const double o = cell / 3.0;  // off the cell boundaries
        scene.withNoise(0.01, 9e-4).floor(o, o, 5.0 + o, 4.0 + o, 0.0).wallX(o, o, 4.0 + o, 0.0, 2.5);
        // The strip: the wall y = 4 m from z = 2 m up, a point every 2 cm along each line.
        std::mt19937 random(seed);
        std::normal_distribution<double> noise(0.0, 0.01);
        for (int line = 0; line < lines; ++line) {
          const double z = 2.0 + 0.12 * line;
          for (double x = 0.3; x < 3.3; x += 0.02) {
            scene.map().insert(Point{x + o, 4.0 + o + noise(random), z + 0.003 * noise(random)}, 9e-4);
          }
        }
        const PlaneDetection detection = detectPlanes(scene.map());
        const Plane* strip = nullptr;
        for (const Plane& plane : detection.planes) {
          if (std::abs(plane.normal.y()) > 0.99 && std::abs(plane.offset + plane.normal.y() * (4.0 + o)) < 0.05) {
            strip = &plane;
          }
        }
        REQUIRE(strip != nullptr);
        // Most of its 3 m x (0.36-0.48 m), not a few columns of it.
        CHECK(strip->area > 0.7);
        CHECK(std::abs(strip->normal.z()) < std::sin(2.0 * 3.14159265358979 / 180.0));
      }
    }
  }
}
