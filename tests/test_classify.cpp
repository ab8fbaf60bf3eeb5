// Plane classes on maps that are not level (issue 19: "classes relative to the floor
// found"): real scans seldom are (PCL's room_scan2 2°, 3DTK's registered frame 4°).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "mlmap/planes/classify.hpp"

using namespace mlmap;

namespace {

// A level patch of the plane with unit normal `normal` through `through`, covering
// x0..x1 × y0..y1 (its outline lifted onto the plane).
Plane levelPatch(const Eigen::Vector3d& normal, const Eigen::Vector3d& through, double x0, double x1, double y0,
                 double y1) {
  Plane plane;
  plane.normal = normal;
  plane.offset = -normal.dot(through);
  auto onPlane = [&](double x, double y) {
    return Eigen::Vector3d(x, y, -(plane.offset + normal.x() * x + normal.y() * y) / normal.z());
  };
  plane.outline = {onPlane(x0, y0), onPlane(x1, y0), onPlane(x1, y1), onPlane(x0, y1)};
  plane.centroid = onPlane((x0 + x1) / 2.0, (y0 + y1) / 2.0);
  plane.area = (x1 - x0) * (y1 - y0);
  return plane;
}

// A plumb patch facing +x at x, covering y0..y1 × z0..z1.
Plane plumbPatch(double x, double y0, double y1, double z0, double z1) {
  Plane plane;
  plane.normal = Eigen::Vector3d::UnitX();
  plane.offset = -x;
  plane.outline = {{x, y0, z0}, {x, y1, z0}, {x, y1, z1}, {x, y0, z1}};
  plane.centroid = {x, (y0 + y1) / 2.0, (z0 + z1) / 2.0};
  plane.area = (y1 - y0) * (z1 - z0);
  return plane;
}

}  // namespace

TEST_CASE("Classes: a floor 2° off level, seen in two patches apart, is floor in both") {
  const double tilt = 2.0 * std::numbers::pi / 180.0;
  const Eigen::Vector3d up(-std::sin(tilt), 0.0, std::cos(tilt));
  std::vector<Plane> planes;
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.0}, 0.0, 3.0, 0.0, 2.0));   // centroid z 0.05
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.0}, 4.5, 6.0, 0.0, 2.0));   // centroid z 0.18
  planes.push_back(levelPatch(up, {0.0, 0.0, 2.5}, 0.0, 6.0, 0.0, 2.0));   // the ceiling
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.75}, 4.6, 5.8, 0.2, 0.8));  // a table over the far patch
  classifyPlanes(planes);
  CHECK(planes[0].label == PlaneClass::Floor);
  CHECK(planes[1].label == PlaneClass::Floor);  // 13 cm above the first in z: 'other' before
  CHECK(planes[2].label == PlaneClass::Ceiling);
  CHECK(planes[3].label == PlaneClass::Table);
}

// 3DTK's corridor at 0.2 m cells, in a frame 2.9° off level: the floor's 20 m² patch near the
// start, a rough 2 m² piece 6 m further on whose centroid lies 0.55 m lower in z but only 0.3 m
// below the floor's plane. "The lowest patches" were taken in z, so the floor's own patch lay
// beyond the search and the rough piece's neighbour was the floor.
TEST_CASE("Classes: the floor of a long corridor 3° off level is the largest patch, not the lowest in z") {
  const double tilt = 3.0 * std::numbers::pi / 180.0;
  const Eigen::Vector3d up(-std::sin(tilt), 0.0, std::cos(tilt));
  std::vector<Plane> planes;
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.0}, 0.0, 8.0, 0.0, 2.5));             // the floor, centroid z 0.21
  planes.push_back(levelPatch(up, {0.0, 0.0, -0.08}, 9.0, 11.0, 0.0, 1.0));          // a far piece, z 0.44
  planes.push_back(levelPatch(up, {0.0, 0.0, -0.33}, 11.0, 12.0, 0.0, 1.0));         // rough, z 0.27
  planes.push_back(levelPatch(up, {0.0, 0.0, 2.6}, 0.0, 12.0, 0.0, 2.5));            // the ceiling
  // In z the rough piece lies 0.06 m above the floor's centroid; the lowest in z is the
  // floor's near end. Turned the other way the far end is lowest:
  for (const double sign : {1.0, -1.0}) {
    CAPTURE(sign);
    std::vector<Plane> seen = planes;
    if (sign < 0.0) {
      const Eigen::Vector3d down_x(std::sin(tilt), 0.0, std::cos(tilt));
      seen[0] = levelPatch(down_x, {0.0, 0.0, 0.0}, 0.0, 8.0, 0.0, 2.5);             // centroid z -0.21
      seen[1] = levelPatch(down_x, {0.0, 0.0, -0.08}, 9.0, 11.0, 0.0, 1.0);          // z -0.60
      seen[2] = levelPatch(down_x, {0.0, 0.0, -0.33}, 11.0, 12.0, 0.0, 1.0);         // z -0.93: lowest by 0.72 m
      seen[3] = levelPatch(down_x, {0.0, 0.0, 2.6}, 0.0, 12.0, 0.0, 2.5);
    }
    classifyPlanes(seen);
    CHECK(seen[0].label == PlaneClass::Floor);
    CHECK(seen[3].label == PlaneClass::Ceiling);
    CHECK(seen[2].label != PlaneClass::Floor);  // 0.33 m below the floor's plane
  }
}

TEST_CASE("Classes: a level patch with the map's surface under it is no floor (a cloud cut above its floor)") {
  // Bobkov's room 2 is cut at z 1.5, above its floor: the lowest level patches are chair
  // seats 0.4 m higher, with their legs and the walls' feet below them.
  const Eigen::Vector3d up(0.0, 0.0, 1.0);
  std::vector<Plane> planes;
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.45}, 0.0, 2.0, 0.0, 2.0));  // seats
  planes.push_back(levelPatch(up, {0.0, 0.0, 1.2}, 2.5, 3.5, 0.0, 1.0));   // a table
  std::vector<SurfaceSample> surface;
  for (int k = 0; k < 100; ++k) surface.push_back({Eigen::Vector3d(0.03 * k, 0.5, 0.1), 1.0});  // legs, wall feet
  for (int k = 0; k < 300; ++k) surface.push_back({Eigen::Vector3d(0.01 * k, 0.5, 0.45), 1.0});
  std::vector<Plane> seen = planes;
  classifyPlanes(seen, {}, surface);
  CHECK(seen[0].label != PlaneClass::Floor);  // floor without the surface samples
  CHECK(seen[1].label != PlaneClass::Table);

  // A real floor with a few stray readings under it (reflections: at most 0.13 % of the
  // points of seven real scans) stays floor.
  std::vector<SurfaceSample> floor_surface(1000, SurfaceSample{Eigen::Vector3d(0.5, 0.5, 0.45), 1.0});
  floor_surface.push_back({Eigen::Vector3d(0.5, 0.5, -0.5), 5.0});
  seen = planes;
  classifyPlanes(seen, {}, floor_surface);
  CHECK(seen[0].label == PlaneClass::Floor);
  CHECK(seen[1].label == PlaneClass::Table);
  classifyPlanes(planes);
  CHECK(planes[0].label == PlaneClass::Floor);  // without samples, as before
}

TEST_CASE("Classes: a ceiling piece beyond a doorway, 9 cm off the ceiling's plane there, is ceiling, a fixture 40 cm below is not") {
  // PCL's room_scan1: the next room's ceiling, seen through a door 4-5 m from the
  // ceiling's centroid, lies 9 cm below the ceiling's plane there (the two lean 1.2° apart
  // in a scan that is not quite flat); it was 'other'.
  const Eigen::Vector3d up(0.0, 0.0, 1.0);
  const double lean = 1.2 * std::numbers::pi / 180.0;
  const Eigen::Vector3d leaning(std::sin(lean), 0.0, std::cos(lean));
  std::vector<Plane> planes;
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.0}, 0.0, 6.0, 0.0, 4.0));          // floor
  planes.push_back(levelPatch(leaning, {3.0, 2.0, 2.9}, 0.0, 6.0, 0.0, 4.0));     // ceiling
  planes.push_back(levelPatch(up, {0.0, 0.0, 2.89}, 7.0, 9.0, 0.0, 4.0));         // beyond the door
  planes.push_back(levelPatch(up, {0.0, 0.0, 2.45}, 2.0, 2.6, 1.0, 1.6));         // a lamp's underside
  classifyPlanes(planes);
  CHECK(planes[0].label == PlaneClass::Floor);
  CHECK(planes[1].label == PlaneClass::Ceiling);
  // Beyond the classes' 6 cm: not ceiling yet, so the level merge leaves it apart.
  CHECK(std::abs(planes[1].normal.dot(planes[2].centroid) + planes[1].offset) > 0.06);
  CHECK(planes[2].label != PlaneClass::Ceiling);
  labelCeilingPieces(planes);
  CHECK(planes[2].label == PlaneClass::Ceiling);
  CHECK(planes[3].label != PlaneClass::Ceiling);
}

TEST_CASE("Classes: steps climb from the floor riser by riser, a desk top a riser above a shelf stays a table") {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  std::vector<Plane> planes;
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.0}, 0.0, 8.0, 0.0, 6.0));   // 0: floor
  planes.push_back(levelPatch(up, {0.0, 0.0, 2.6}, 0.0, 8.0, 0.0, 6.0));   // 1: ceiling
  // A flight of four treads 0.3 m deep and 0.17 m high along x from the floor.
  for (int k = 1; k <= 4; ++k) {
    planes.push_back(levelPatch(up, {0.0, 0.0, 0.17 * k}, 6.0 + 0.3 * (k - 1), 6.0 + 0.3 * k, 4.0, 5.0));  // 2-5
  }
  // A desk top at 0.74 m over a keyboard shelf at 0.60 m (PCL's room scans: desks a riser
  // above such a piece were steps), and a chair seat at 0.46 m beside it.
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.74}, 1.0, 2.6, 0.5, 1.3));  // 6: desk
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.60}, 1.4, 2.0, 1.3, 1.6));  // 7: shelf
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.46}, 1.6, 2.1, 1.8, 2.3));  // 8: seat
  classifyPlanes(planes);
  CHECK(planes[0].label == PlaneClass::Floor);
  CHECK(planes[1].label == PlaneClass::Ceiling);
  for (int k = 2; k <= 5; ++k) CHECK(planes[k].label == PlaneClass::Step);
  CHECK(planes[6].label == PlaneClass::Table);  // 'step' before
  CHECK(planes[7].label == PlaneClass::Table);
  CHECK(planes[8].label == PlaneClass::Table);

  // Without a floor (the map's surface reaches below every patch) a flight of three or
  // more is still steps; the desk, shelf and seat, two riser links, are too (a flight of
  // three), but a desk with only a shelf a riser below it is not (Bobkov's room 2: its
  // table and sideboard tops were steps).
  std::vector<Plane> floorless(planes.begin() + 2, planes.end());
  const std::vector<SurfaceSample> below{{Eigen::Vector3d(3.0, 3.0, -1.0), 1000.0}};
  classifyPlanes(floorless, {}, below);
  for (int k = 0; k < 4; ++k) CHECK(floorless[k].label == PlaneClass::Step);
  std::vector<Plane> desk_and_shelf{planes[6], planes[7]};
  classifyPlanes(desk_and_shelf, {}, below);
  CHECK(desk_and_shelf[0].label == PlaneClass::Other);  // 'step' before
  CHECK(desk_and_shelf[1].label == PlaneClass::Other);
}

TEST_CASE("Classes: a table over the chairs' seats, a riser above them, and a sideboard beside it are no flight") {
  // Bobkov's room 2 at 10 cm, cut above its floor: the table top (z 2.15), the seats'
  // patch partly under it (1.90: 0.25 below, one riser) and the sideboard's top beside it
  // (1.97) were a flight of three, all 'step'. Treads lie side by side, not one over the other.
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  std::vector<Plane> planes;
  planes.push_back(levelPatch(up, {0.0, 0.0, 2.15}, 0.5, 3.5, 0.6, 2.7));    // table top
  planes.push_back(levelPatch(up, {0.0, 0.0, 1.90}, 0.3, 2.3, 1.6, 3.2));    // seats, half under it
  planes.push_back(levelPatch(up, {0.0, 0.0, 1.97}, -1.7, 0.1, -0.2, 0.9));  // sideboard
  const std::vector<SurfaceSample> below{{Eigen::Vector3d(1.0, 1.0, 0.5), 1000.0}};
  classifyPlanes(planes, {}, below);
  for (const Plane& plane : planes) CHECK(plane.label == PlaneClass::Other);  // 'step' before

  // Treads of a flight turned 45° to the grid still are one: their outlines' boxes
  // overlap, the outlines themselves only in a strip along each riser.
  std::vector<Plane> flight;
  const double c = std::sqrt(0.5);
  for (int k = 0; k < 4; ++k) {
    Plane tread = levelPatch(up, {0.0, 0.0, 0.17 * (k + 1)}, 0.0, 0.0, 0.0, 0.0);
    const auto at = [&](double u, double v) { return Eigen::Vector3d(c * (u - v), c * (u + v), 0.17 * (k + 1)); };
    const double u0 = 0.3 * k - 0.05, u1 = 0.3 * (k + 1) + 0.05;  // outlines rounded out by half a 10 cm cell
    tread.outline = {at(u0, 0.0), at(u1, 0.0), at(u1, 1.0), at(u0, 1.0)};
    tread.centroid = at(0.5 * (u0 + u1), 0.5);
    tread.area = 0.3;
    flight.push_back(tread);
  }
  const std::vector<SurfaceSample> under_flight{{Eigen::Vector3d(0.0, 0.5, -1.0), 1000.0}};
  classifyPlanes(flight, {}, under_flight);
  for (const Plane& tread : flight) CHECK(tread.label == PlaneClass::Step);
}

TEST_CASE("Classes: a flight from the floor goes on past a tread that came as a tilted band") {
  // plane_seg's ANYmal stairs at 10 cm cells: the second tread's patch held the riser below
  // it and leaned 16.5°; the flight stopped there, and the third tread (0.5 m over the floor)
  // and the landing above it were 'table'.
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  std::vector<Plane> planes;
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.0}, 0.0, 1.3, 0.0, 1.8));  // 0: floor
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.18}, 1.3, 1.8, 0.0, 1.8));  // 1: tread 1
  // 2: tread 2 and the riser under it, leaning 16.5° (rising 0.25 m over 0.8 m along x)
  const double lean = 16.5 * std::numbers::pi / 180.0;
  planes.push_back(levelPatch(Eigen::Vector3d(-std::sin(lean), 0.0, std::cos(lean)), {2.2, 0.9, 0.36}, 1.8, 2.6, 0.0,
                              1.8));
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.52}, 2.6, 3.0, 0.0, 1.8));  // 3: tread 3
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.70}, 3.0, 5.0, 0.0, 2.4));  // 4: the landing
  classifyPlanes(planes);
  CHECK(planes[0].label == PlaneClass::Floor);
  CHECK(planes[1].label == PlaneClass::Step);
  CHECK(planes[2].label == PlaneClass::Step);  // 'other' before
  CHECK(planes[3].label == PlaneClass::Step);  // 'table' before
  CHECK(planes[4].label == PlaneClass::Floor);  // 'table' before session 51, 'step' before 52: a landing

  // The same band beside a desk, with no flight climbing to it from the floor, is no step.
  std::vector<Plane> furniture{planes[0], planes[2], planes[3]};
  furniture[1].centroid.x() += 3.0;
  for (Eigen::Vector3d& corner : furniture[1].outline) corner.x() += 3.0;
  furniture[1].offset = -furniture[1].normal.dot(furniture[1].centroid);
  classifyPlanes(furniture);
  CHECK(furniture[1].label == PlaneClass::Other);
}

TEST_CASE("Classes: a ceiling piece over a floor with a larger landing above it is measured from the floor") {
  // A landing is floor at its own height (classifyPlanes): here larger than the floor below
  // it, 0.7 m higher. The ceiling piece 2.3 m over the floor is only 1.6 m over the landing,
  // under the 1.8 m a storey asks; measured from the landing it stayed 'other'.
  const Eigen::Vector3d up(0.0, 0.0, 1.0);
  std::vector<Plane> planes;
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.0}, 0.0, 2.0, 0.0, 2.0));   // 0: floor, 4 m²
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.7}, 3.0, 6.0, 0.0, 3.0));   // 1: landing, 9 m²
  planes.push_back(levelPatch(up, {0.0, 0.0, 2.45}, 0.0, 6.0, 0.0, 3.0));  // 2: ceiling
  planes.push_back(levelPatch(up, {0.0, 0.0, 2.3}, 7.0, 9.0, 0.0, 3.0));   // 3: beyond a doorway
  planes[0].label = PlaneClass::Floor;
  planes[1].label = PlaneClass::Floor;
  planes[2].label = PlaneClass::Ceiling;
  planes[3].label = PlaneClass::Other;
  std::vector<Plane> unflagged = planes;
  labelCeilingPieces(unflagged);
  CHECK(unflagged[3].label == PlaneClass::Other);  // the landing taken for the floor
  const std::vector<std::uint8_t> landings{0, 1, 0, 0};
  labelCeilingPieces(planes, {}, landings);
  CHECK(planes[3].label == PlaneClass::Ceiling);
}

TEST_CASE("Classes: a flight seen from below is its bands and its risers, drawer fronts in one plane are none") {
  // OctoMap's fr079 at 10 cm cells: the lower steps of the staircase seen from below came as
  // risers 20 cm tall, one patch each, beside the bands (riser and nosing) of the upper ones,
  // and were 'other'; two bands alone are no flight.
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d band_normal = Eigen::Vector3d(-0.6, 0.0, 0.8).normalized();
  std::vector<Plane> planes;
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.0}, 0.0, 5.9, 0.0, 3.0));            // 0: floor
  planes.push_back(plumbPatch(6.1, 0.0, 3.0, 0.27, 0.47));                          // 1: riser
  planes.push_back(plumbPatch(6.43, 0.0, 3.0, 0.38, 0.58));                         // 2: riser
  planes.push_back(levelPatch(band_normal, {6.715, 1.5, 0.61}, 6.53, 6.9, 0.0, 3.0));  // 3: band
  planes.push_back(levelPatch(band_normal, {7.125, 1.5, 0.78}, 6.95, 7.3, 0.0, 3.0));  // 4: band
  classifyPlanes(planes);
  CHECK(planes[0].label == PlaneClass::Floor);
  for (std::size_t k = 1; k < planes.size(); ++k) {
    CAPTURE(k);
    CHECK(planes[k].label == PlaneClass::Step);  // 'other' before
  }
  // Three drawer fronts stacked in one plane, each a riser above the next: no flight.
  std::vector<Plane> drawers{planes[0], plumbPatch(2.0, 1.0, 1.5, 0.1, 0.28), plumbPatch(2.0, 1.0, 1.5, 0.3, 0.48),
                             plumbPatch(2.0, 1.0, 1.5, 0.5, 0.68)};
  classifyPlanes(drawers);
  for (std::size_t k = 1; k < drawers.size(); ++k) {
    CAPTURE(k);
    CHECK(drawers[k].label == PlaneClass::Other);
  }
}

TEST_CASE("Classes: a wall seen in pieces is measured over all of them, not over its outline's piece") {
  // Bobkov's room 2 at 5 cm: a wall seen between shelves is one patch whose blocks span
  // z 1.50-3.44 and whose outline (the largest piece) spans 2.44-3.44; it was 'other'.
  std::vector<Plane> planes{plumbPatch(-1.7, 1.9, 3.6, 2.45, 3.44)};  // 0.99 m tall
  std::vector<Plane> seen = planes;
  classifyPlanes(seen);
  CHECK(seen[0].label == PlaneClass::Other);  // as before, where nothing else is known
  planes[0].bounds.extend(Eigen::Vector3d(-1.7, 1.9, 1.50)).extend(Eigen::Vector3d(-1.7, 3.6, 3.44));
  classifyPlanes(planes);
  CHECK(planes[0].label == PlaneClass::Wall);
  // A low riser-sized piece with a stray cell far above it is no wall.
  std::vector<Plane> low{plumbPatch(0.0, 0.0, 1.0, 0.0, 0.17)};
  low[0].bounds.extend(Eigen::Vector3d(0.0, 0.0, 0.0)).extend(Eigen::Vector3d(0.0, 1.0, 0.9));
  classifyPlanes(low);
  CHECK(low[0].label != PlaneClass::Wall);
}

TEST_CASE("Classes: a cloud cut above its floor measures its tables from where its walls end") {
  // Bobkov's room 2: cut at z 1.50, its three walls end there; the table top lies 0.68 m and
  // the sideboard 0.47 m over it, the seats' patch (half under the table) 0.40 m. They were
  // all 'other': without a floor nothing was measured.
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  std::vector<Plane> planes;
  planes.push_back(levelPatch(up, {0.0, 0.0, 2.18}, 0.5, 3.5, 0.6, 2.7));    // table top
  planes.push_back(levelPatch(up, {0.0, 0.0, 1.97}, -1.7, 0.1, -0.2, 0.9));  // sideboard
  planes.push_back(levelPatch(up, {0.0, 0.0, 2.90}, -1.0, 0.0, 2.0, 3.0));   // a shelf 1.4 m up
  planes.push_back(plumbPatch(4.72, -0.1, 2.9, 1.50, 3.44));
  planes.push_back(plumbPatch(-1.70, 1.9, 3.6, 1.52, 3.44));
  std::vector<SurfaceSample> surface;  // nothing below the cut
  for (int k = 0; k < 100; ++k) surface.push_back({Eigen::Vector3d(0.03 * k, 0.5, 1.5 + 0.019 * k), 1.0});
  std::vector<Plane> seen = planes;
  const HeightReference reference = classifyPlanes(seen, {}, surface);
  CHECK(reference.kind == HeightReference::Kind::WallsFoot);
  CHECK(reference.height == doctest::Approx(1.51).epsilon(1e-9));
  CHECK(seen[0].label == PlaneClass::Table);
  CHECK(seen[1].label == PlaneClass::Table);
  CHECK(seen[2].label == PlaneClass::Other);
  CHECK(seen[3].label == PlaneClass::Wall);
  CHECK(seen[4].label == PlaneClass::Wall);
  for (const Plane& plane : seen) CHECK(plane.label != PlaneClass::Floor);

  // One wall alone, or walls whose feet disagree (seen above furniture), fix no height.
  seen = {planes[0], planes[1], planes[3]};
  CHECK(classifyPlanes(seen, {}, surface).kind == HeightReference::Kind::None);
  CHECK(seen[0].label == PlaneClass::Other);
  seen = planes;
  seen[4] = plumbPatch(-1.70, 1.9, 3.6, 2.20, 3.44);
  classifyPlanes(seen, {}, surface);
  CHECK(seen[0].label == PlaneClass::Other);
  // Walls that end together over more of the map's surface below are no floor's height.
  std::vector<SurfaceSample> below = surface;
  below.push_back({Eigen::Vector3d(1.0, 1.0, 0.8), 50.0});
  seen = planes;
  classifyPlanes(seen, {}, below);
  CHECK(seen[0].label == PlaneClass::Other);
}
