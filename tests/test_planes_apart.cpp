// Level surfaces apart (issue 19: "two separate tables ... form one patch"): the patch
// split connects blocks across a one-cell gap, and the coplanar merge pieces within
// 0.3 m, so two desks a hand apart at one height were one table. Where the floor shows
// between them they are two; a desk whose middle nobody saw (a monitor's shadow) is one.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "mlmap/planes/ermsm.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

TEST_CASE("eRMSM: two desks 0.25 m apart at one height, the floor seen between them, are two patches") {
  for (const double cell : {0.05, 0.1}) {
    for (const unsigned seed : {1U, 2U}) {
      CAPTURE(cell);
      CAPTURE(seed);
      test::PlaneSceneBuilder scene(cell, 0.01, seed);
      // Offsets of a third of a cell: the gap does not fall on cell boundaries.
      const double o = cell / 3.0;
      scene.withNoise(0.01, 9e-4)
          .floor(o, o, 5.0 + o, 4.0 + o, 0.0)
          .floor(o, o, 5.0 + o, 4.0 + o, 2.6)  // the ceiling over them
          .floor(1.0 + o, 1.0 + o, 2.4 + o, 1.75 + o, 0.75)
          .floor(2.65 + o, 1.0 + o, 4.05 + o, 1.75 + o, 0.75);
      const PlaneDetection detection = detectPlanes(scene.map());
      const std::vector<const Plane*> desks = test::levelPatchesAt(detection, 0.75);
      REQUIRE(desks.size() >= 2);
      // Each about its own 1.05 m², not the two together.
      CHECK(desks[0]->area < 1.5);
      CHECK(desks[1]->area > 0.8);
    }
  }
}

TEST_CASE("eRMSM: a desk whose middle strip nobody saw is one patch") {
  for (const double cell : {0.05, 0.1}) {
    CAPTURE(cell);
    test::PlaneSceneBuilder scene(cell, 0.01, 1);
    const double o = cell / 3.0;
    // The desk's two halves 0.2 m apart with nothing seen between them: no floor under
    // the desk (it hides it), none of the strip.
    scene.withNoise(0.01, 9e-4)
        .floor(o, o, 5.0 + o, 1.0 + o, 0.0)
        .floor(o, 1.75 + o, 5.0 + o, 4.0 + o, 0.0)
        .floor(o, o, 5.0 + o, 4.0 + o, 2.6)
        .floor(1.0 + o, 1.0 + o, 2.0 + o, 1.75 + o, 0.75)
        .floor(2.2 + o, 1.0 + o, 3.2 + o, 1.75 + o, 0.75);
    const PlaneDetection detection = detectPlanes(scene.map());
    const std::vector<const Plane*> desks = test::levelPatchesAt(detection, 0.75);
    REQUIRE(!desks.empty());
    CHECK(desks[0]->area > 1.3);  // both halves, 1.5 m² (and their edge cells)
  }
}

// A wall's pieces either side of a doorway (issue 19; 3DTK's hall wall: two patches either
// side of doorways 0.45 and 0.6 m wide whose lintels the scan did not reach) are one wall;
// two walls in line with a room's width between them stay two.
TEST_CASE("eRMSM: a wall's pieces either side of a doorway are one patch, walls 2 m apart in line are two") {
  for (const double cell : {0.05, 0.1}) {
    for (const unsigned seed : {1U, 2U}) {
      CAPTURE(cell);
      CAPTURE(seed);
      const double o = cell / 3.0;
      for (const double gap : {0.7, 2.0}) {
        CAPTURE(gap);
        test::PlaneSceneBuilder scene(cell, 0.01, seed);
        // The wall y = 2 from x 0 to 7 with an opening `gap` wide at x 3, full height
        // (its lintel unseen), the floor seen through it beyond the wall.
        scene.withNoise(0.01, 9e-4)
            .floor(o, o, 7.0 + o, 2.0 + o, 0.0)
            .floor(3.0 + o, 2.0 + o, 3.0 + gap + o, 3.0 + o, 0.0)
            .wallY(2.0 + o, o, 3.0 + o, 0.0, 2.4)
            .wallY(2.0 + o, 3.0 + gap + o, 7.0 + o, 0.0, 2.4);
        const PlaneDetection detection = detectPlanes(scene.map());
        const std::vector<const Plane*> walls = test::wallPatchesAtY(detection, 2.0);
        REQUIRE(!walls.empty());
        if (gap < 1.0) {
          CHECK(walls.size() == 1);
          CHECK(walls[0]->area > 0.9 * (7.0 - gap) * 2.4);
        } else {
          CHECK(walls.size() == 2);
        }
      }
    }
  }
}

// Issue 19: "two side corridors' end walls 15.5 m apart (the solid between them never
// scanned) become one patch": coplanar walls of two rooms, nothing seen beside the gap
// between them. Such a gap is bridged only where the pieces cover a third of the joined
// stretch (here 4 m of 14).
TEST_CASE("eRMSM: two corridors' end walls in line, 10 m of unseen solid between them, are two patches") {
  for (const double cell : {0.05, 0.1}) {
    for (const unsigned seed : {1U, 2U}) {
      CAPTURE(cell);
      CAPTURE(seed);
      const double o = cell / 3.0;
      test::PlaneSceneBuilder scene(cell, 0.01, seed);
      // Two side corridors 2 m wide, x 0-2 and x 12-14, each with its floor up to its end
      // wall at y = 6; between them (x 2-12) a block of rooms nobody entered.
      scene.withNoise(0.01, 9e-4)
          .floor(o, o, 2.0 + o, 6.0 + o, 0.0)
          .floor(12.0 + o, o, 14.0 + o, 6.0 + o, 0.0)
          .wallY(6.0 + o, o, 2.0 + o, 0.0, 2.5)
          .wallY(6.0 + o, 12.0 + o, 14.0 + o, 0.0, 2.5);
      const PlaneDetection detection = detectPlanes(scene.map());  // the walls point into it
      const std::vector<const Plane*> walls = test::wallPatchesAtY(detection, 6.0);
      REQUIRE(walls.size() == 2);
      for (const Plane* wall : walls) CHECK(wall->area == doctest::Approx(2.0 * 2.5).epsilon(0.15));
    }
  }
}
