// Per-point labels at a face's foot: the floor's points where a cabinet, a wall or a box
// side stands on it, its blocks cells off (a turned face, a far floor's scan lines), and a
// face that goes on below the point (a chair's back before a desk) keeping its own.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "mlmap/planes/point_labels.hpp"
#include "scanned_scene.hpp"

using namespace mlmap;
using test::boxRoomScene;
using test::FloorOn;
using test::floorPointsOn;
using test::Scanned;
using test::surfaceOfPatches;

TEST_CASE("Point labels: floor points at the foot of a turned cabinet, whose face took the floor's blocks there, stay the floor's") {
  // The cabinet room turned 2° to the grid. Along a face's foot the detector gives some
  // cells' level blocks (the floor's strip in that column) to the face, and the floor's own
  // blocks lie two cells off: a floor point there had the face as its only candidate (1
  // here before; turned 10°, 3 before and 1 now; the simulated lab turned 2-10°: single
  // floor points on cabinets' faces, each then "touching" the floor in issue 19's held-out
  // measure).
  static const Scanned scanned(
      boxRoomScene(R"({"x": 2.5, "y": 2.0, "yaw_deg": 150}, {"x": 3.5, "y": 3.2, "yaw_deg": 200},
                      {"x": 2.0, "y": 3.5, "yaw_deg": -90})",
                   R"({"type": "box", "class": "other", "min": [0, 1.0, 0], "max": [0.5, 3.0, 1.8], "omit": ["bottom", "x-"]},
      {"type": "box", "class": "other", "min": [4.0, 1.0, 0], "max": [4.6, 1.5, 0.5], "omit": ["bottom"]})"),
      "turned_cabinet.json", 2.0);
  const FloorOn counted = floorPointsOn(scanned, 6);  // the cabinets' faces
  const std::size_t floor = counted.floor, floor_on_faces = counted.on_others;
  MESSAGE(floor << " floor points, " << floor_on_faces << " on the cabinet's patches");
  REQUIRE(floor > 10000);
  CHECK(floor_on_faces == 0);
}

TEST_CASE("Point labels: floor points at a far wall's foot go to the floor, whose blocks lie two cells off") {
  // A 15.8 x 9.3 m hall scanned from two poses near one end (as bench/planes_sweep.py's
  // hall-1), turned to the grid. Along a far wall's foot the floor is seen by scan lines
  // 10-30 cm apart: its blocks there lie two cells or more from where a floor point's beam
  // meets the floor, and the floor was looked for one cell round that place unless a
  // vertical block ended there. A wall foot's cell holds the floor's strip as a level block
  // of the wall's patch (as at a face's foot, where the floor's own points were already
  // looked for two cells round): the floor counts two cells round where its beam meets it.
  // 30 and 34 floor points on the walls before (turned 5 and 22.5°), 27 and 30 now; the rest
  // lie within both planes' range noise, where the larger surface, the wall, keeps them.
  const std::string hall =
      test::hallScene(15.76, 9.27, 3.0, R"({"x": 2.04, "y": 4.98, "yaw_deg": -21.1}, {"x": 3.99, "y": 5.63, "yaw_deg": 29.5})");
  std::size_t floor_on_walls_all = 0;
  for (const double turn : {5.0, 22.5}) {
    CAPTURE(turn);
    const Scanned scanned(hall, "hall_" + std::to_string(static_cast<int>(turn)) + ".json", turn);
    const FloorOn counted = floorPointsOn(scanned, 2);  // the walls
    MESSAGE(turn << " deg: " << counted.floor << " floor points, " << counted.on_others << " on the walls' patches");
    REQUIRE(counted.floor > 10000);
    floor_on_walls_all += counted.on_others;
  }
  CHECK(floor_on_walls_all <= 60);
}

TEST_CASE("Point labels: floor points at a far box side's foot go to the floor, whose scan lines lie cells apart there") {
  // A 17.5 x 7.2 m hall (bench/planes_sweep.py's hall-2) scanned from near one end, a
  // sideboard along a side wall 6-9 m out. There the floor's scan lines lie 15-30 cm
  // apart: a line that meets the floor at the sideboard's end face has its floor points in
  // the face's vertical blocks, and the floor's nearest block three cells or more along
  // the line. Looked for two cells round, the floor was no candidate and the face took
  // them (each such point makes the face "touch" the floor in issue 19's held-out measure);
  // looked for as far as the floor's scan lines lie apart (the detector's sparse gap) it is.
  // Since the foot of a face on a level patch without blocks near (LevelStrips::
  // stripOnUnseenLevel) the floor keeps them looked for two cells round too: 0 either way.
  const std::string hall = test::hallScene(
      17.55, 7.22, 3.33, R"({"x": 2.41, "y": 5.27, "yaw_deg": -3.4}, {"x": 3.57, "y": 5.02, "yaw_deg": 15.2})",
      R"({"type": "box", "class": "other", "min": [8.52, 0.0, 0.0], "max": [11.07, 0.45, 0.92], "omit": ["bottom", "y-"]})");
  std::size_t before_all = 0, after_all = 0;
  for (const double turn : {0.0, 3.0, 7.0, 15.0, 22.5, 30.0}) {
    CAPTURE(turn);
    const Scanned scanned(hall, "hall_sideboard_" + std::to_string(static_cast<int>(10 * turn)) + ".json", turn);
    PointLabelRefinement two_cells = scanned.options();
    two_cells.level_gap = 0.0;
    const FloorOn before = floorPointsOn(scanned, 6, two_cells);  // the sideboard's faces
    const FloorOn counted = floorPointsOn(scanned, 6);
    MESSAGE(turn << " deg: " << counted.floor << " floor points; on the sideboard's patches " << before.on_others
                 << " looked for two cells round, " << counted.on_others << " as far as the floor's lines lie apart");
    REQUIRE(counted.floor > 10000);
    before_all += before.on_others;
    after_all += counted.on_others;
  }
  CHECK(after_all <= before_all);
  CHECK(after_all <= 2);
}

TEST_CASE("Point labels: halfway up a chair's back, the desk top behind it does not take the strip at its height") {
  // Part of bench/office_rooms.py's office-23 (a desk turned 43° and the chair before it,
  // moved 0.62 and 0.75 of a 5 cm cell off the grid, as planes_sweep.py's seed 1): the
  // chair's back (0.59-1.01 m) turned 50° stands 0.3 m before the desk's top (0.72 m). A
  // turned face's cells hold ladders of its level blocks, so the search past two cells at a
  // face's foot (level_gap) ran halfway up the back, and the desk's top took the back's strip
  // at its height (136 points; in the sweep the back then lost its match). It runs only
  // where no block of the face lies below the point.
  static const Scanned scanned(R"({"scan_pattern": {"angular_step_deg": 0.25, "tilt_start_deg": -46, "tilt_end_deg": 46, "tilt_step_deg": 0.4, "range_sigma": 0.01, "mount_height": 1.2, "seed": 23},
 "poses": [{"x": 5.951, "y": 1.684, "yaw_deg": 60.0}, {"x": 1.056, "y": 1.832, "yaw_deg": -109.8}, {"x": 4.408, "y": 2.182, "yaw_deg": -140.4}],
 "surfaces": [
  {"type": "rectangle", "class": "floor", "min": [0.0309, 0.0377, 0], "max": [8.6843, 4.5624, 0]},
  {"type": "rectangle", "class": "ceiling", "min": [0.0309, 0.0377, 2.5285], "max": [8.6843, 4.5624, 2.5285]},
  {"type": "rectangle", "class": "wall", "min": [0.0309, 0.0377, 0], "max": [0.0309, 4.5624, 2.5285], "facing": "+x"},
  {"type": "rectangle", "class": "wall", "min": [8.6843, 0.0377, 0], "max": [8.6843, 4.5624, 2.5285], "facing": "-x"},
  {"type": "rectangle", "class": "wall", "min": [0.0309, 0.0377, 0], "max": [8.6843, 0.0377, 2.5285], "facing": "+y"},
  {"type": "rectangle", "class": "wall", "min": [0.0309, 4.5624, 0], "max": [8.6843, 4.5624, 2.5285], "facing": "-y"},
  {"type": "box", "class": "other", "center": [2.2087, 2.8162, 0.7249], "size": [1.202, 0.7723, 0.03], "yaw_deg": 43.31, "classes": {"top": "table"}},
  {"type": "cylinder", "center": [2.0384, 2.1937], "radius": 0.025, "z": [0.0, 0.7099]},
  {"type": "cylinder", "center": [1.5772, 2.6829], "radius": 0.025, "z": [0.0, 0.7099]},
  {"type": "cylinder", "center": [2.8403, 2.9496], "radius": 0.025, "z": [0.0, 0.7099]},
  {"type": "cylinder", "center": [2.3791, 3.4388], "radius": 0.025, "z": [0.0, 0.7099]},
  {"type": "box", "class": "other", "center": [2.7089, 2.0032, 0.4663], "size": [0.46, 0.46, 0.06], "yaw_deg": 50.15},
  {"type": "box", "class": "other", "center": [2.9008, 1.843, 0.7963], "size": [0.44, 0.04, 0.42], "yaw_deg": 50.15},
  {"type": "cylinder", "center": [2.7089, 2.0032], "radius": 0.03, "z": [0.05, 0.4363]}
 ]})", "office23_chair.json");
  const std::vector<std::int32_t> labels = scanned.pointLabels(scanned.options());
  std::map<std::int32_t, bool> level;
  for (const Plane& plane : scanned.detection.planes) level[plane.id] = std::abs(plane.normal.z()) > 0.966;
  // The back's points: within 2 cm of its box, below its top edge.
  const double yaw = 50.15 * M_PI / 180.0;
  const Eigen::Vector2d centre(2.9008, 1.843), u(std::cos(yaw), std::sin(yaw)), v(-std::sin(yaw), std::cos(yaw));
  std::size_t back = 0, back_on_level = 0;
  for (std::size_t k = 0; k < scanned.points.size(); ++k) {
    const Point& p = scanned.points[k];
    const Eigen::Vector2d d = p.head<2>() - centre;
    if (std::abs(d.dot(u)) > 0.24 || std::abs(d.dot(v)) > 0.04 || p.z() < 0.57 || p.z() > 0.99) continue;
    ++back;
    back_on_level += labels[k] > 0 && level[labels[k]] ? 1 : 0;
  }
  MESSAGE(back << " points of the chair's back below its top edge, " << back_on_level << " on level patches");
  REQUIRE(back > 1000);
  CHECK(back_on_level <= 5);
}

TEST_CASE("Point labels: floor points at a cabinet's foot go to the floor where its strip there is an island on no patch") {
  // Part of bench/office_rooms.py's office-16 (held out): a cabinet 2 m tall against a wall,
  // its front seen head on. The scanners see no floor within about a metre of themselves, so
  // the floor before the cabinet is a strip seen from afar, cells away from the floor's
  // patch and on no patch itself: the floor was no candidate at the foot and the front took
  // the strip's points within its tolerance (9 here; 31-79 in every variant of office-16 in
  // bench/planes_sweep.py, each a false plane touching the floor in issue 19's measure).
  static const Scanned scanned(
      test::hallScene(7.87, 6.85, 2.69,
                      R"({"x": 6.23, "y": 1.58, "yaw_deg": 89.6}, {"x": 3.22, "y": 2.16, "yaw_deg": -171.6}, {"x": 2.0, "y": 3.24, "yaw_deg": 126.3})",
                      R"({"type": "box", "class": "other", "min": [3.25, 0.0, 0.0], "max": [5.2, 0.45, 2.06], "omit": ["bottom", "y-"]})"),
      "office16_cabinet.json");
  // The floor's points before the front (y 0.45-0.55), and how many the floor's patch's
  // blocks collected.
  const std::vector<std::int32_t> block_labels = scanned.blockLabels();
  std::map<std::int32_t, std::int32_t> surface_of = surfaceOfPatches(block_labels, scanned.truth);
  std::size_t strip = 0, strip_in_floor = 0;
  for (std::size_t k = 0; k < scanned.points.size(); ++k) {
    const Point& p = scanned.points[k];
    if (scanned.truth[k] != 0 || p.x() < 3.3 || p.x() > 5.15 || p.y() < 0.45 || p.y() > 0.55) continue;
    ++strip;
    strip_in_floor += block_labels[k] > 0 && surface_of[block_labels[k]] == 0 ? 1 : 0;
  }
  const FloorOn counted = floorPointsOn(scanned, 6);  // the cabinet's faces
  MESSAGE(strip << " floor points before the front, " << strip_in_floor << " in the floor's blocks; "
                << counted.on_others << " of the floor's on the cabinet's patches");
  REQUIRE(counted.floor > 10000);
  REQUIRE(strip > 20);
  REQUIRE(strip_in_floor == 0);  // the island: the case this is about
  CHECK(counted.on_others <= 2);
}

TEST_CASE("Point labels: a desk keeps its strip at a monitor's foot where a leg below lies on the monitor's plane") {
  // Part of bench/office_rooms.py's office-14 (held out): a monitor 0.33 m tall on a desk's
  // top, and one of the desk's legs under the top's edge on the monitor's plane. The leg's
  // points joined the monitor's patch through their column, so the monitor's lowest point on
  // its plane lay at the floor: it no longer stood on the desk (the foot rule), and the
  // monitor's patch took the desk's points within its tolerance (23 here aligned, 24 turned
  // 10°; 127-353 in office-14's variants of bench/planes_sweep.py, each a false plane
  // touching the desk in issue 19's measure). The foot is also where the face's points start
  // (their 2nd percentile).
  const std::string scene = test::hallScene(
      7.3096, 6.1945, 2.9564, R"({"x": 4.137, "y": 2.247, "yaw_deg": 65.845}, {"x": 6.364, "y": 1.703, "yaw_deg": -169.954}, {"x": 2.804, "y": 2.746, "yaw_deg": -134.229})",
      R"({"center": [1.2104, 3.304, 0.7133], "class": "other", "classes": {"top": "table"}, "size": [1.2811, 0.7353, 0.03], "type": "box", "yaw_deg": -63.5136},
         {"center": [0.6627, 3.6909], "radius": 0.025, "type": "cylinder", "z": [0.0, 0.6983]},
         {"center": [1.2314, 3.9742], "radius": 0.025, "type": "cylinder", "z": [0.0, 0.6983]},
         {"center": [1.1895, 2.6337], "radius": 0.025, "type": "cylinder", "z": [0.0, 0.6983]},
         {"center": [1.7581, 2.9171], "radius": 0.025, "type": "cylinder", "z": [0.0, 0.6983]},
         {"center": [1.3352, 3.5415, 0.9283], "class": "other", "size": [0.55, 0.05, 0.33], "type": "box", "yaw_deg": -67.7556})");
  constexpr std::int32_t kDeskTop = 7;  // the desk box's top (its bottom is 6), at 0.728 m
  constexpr std::int32_t kMonitor = 12;  // the monitor box's faces are 12-17
  for (const double turn : {0.0, 10.0}) {
    CAPTURE(turn);
    const Scanned scanned(scene, "office14_monitor_" + std::to_string(static_cast<int>(turn)) + ".json", turn, 0.01);
    const std::vector<std::int32_t> labels = scanned.pointLabels(scanned.labelOptions());
    std::map<std::int32_t, std::int32_t> surface_of = surfaceOfPatches(labels, scanned.truth);
    std::size_t desk = 0, desk_on_monitor = 0;
    for (std::size_t k = 0; k < scanned.points.size(); ++k) {
      if (scanned.truth[k] != kDeskTop) continue;
      REQUIRE(std::abs(scanned.points[k].z() - 0.728) < 0.06);
      ++desk;
      desk_on_monitor += labels[k] > 0 && surface_of[labels[k]] >= kMonitor ? 1 : 0;
    }
    MESSAGE(turn << " deg: " << desk << " points of the desk's top, " << desk_on_monitor << " on the monitor's patches");
    REQUIRE(desk > 500);
    CHECK(desk_on_monitor <= 2);
  }
}

TEST_CASE("Point labels: floor points below the floor's plane at a cabinet's foot are the floor's tail, not the front's") {
  // Part of bench/office_rooms.py's office-15 (held out) with 3 cm of range noise: a cabinet
  // 2.1 m tall against a wall, its front seen head on, larger than the floor. The floor's
  // points 1.6-5.3 cm below its plane, past its tolerance, lay within the front's: the tail
  // rules give such a point to the larger surface only, and the front took it (1-2 in each
  // turn here; 1-7 in 6 of office-14's and office-15's 24 variants in bench/planes_sweep.py,
  // each a false plane touching the floor in issue 19's measure). The front stands on the
  // floor: below the floor's plane it is not.
  const std::string scene = test::hallScene(
      5.8872, 3.6134, 2.6655, R"({"x": 1.75, "y": 1.992, "yaw_deg": -39.566}, {"x": 0.988, "y": 1.193, "yaw_deg": -117.352}, {"x": 4.703, "y": 1.036, "yaw_deg": -112.729})",
      R"({"class": "other", "max": [3.3146, 0.45, 2.087], "min": [1.7201, 0.0, 0.0], "omit": ["bottom", "y-"], "type": "box"})", 0.03);
  std::size_t floor_on_faces = 0;
  for (const double turn : {0.0, 5.0, 10.0, 20.0, 30.0}) {
    CAPTURE(turn);
    const Scanned scanned(scene, "office15_cabinet_" + std::to_string(static_cast<int>(turn)) + ".json", turn, 0.03);
    const FloorOn counted = floorPointsOn(scanned, 6, scanned.labelOptions());  // the cabinet's faces
    MESSAGE(turn << " deg: " << counted.floor << " floor points, " << counted.on_others << " on the cabinet's patches");
    REQUIRE(counted.floor > 3000);
    floor_on_faces += counted.on_others;
  }
  CHECK(floor_on_faces == 0);
}

TEST_CASE("Point labels: a narrow top keeps its rim where the front's noise fills the cells under it") {
  // Part of bench/office_rooms.py's office-72 with 3 cm of range noise: a sideboard 45 cm deep
  // against a wall, its front seen head on. The front's noise spreads ±6 cm across its plane, so
  // the cell rows behind it under the top's rim hold the front's noise as level blocks of the
  // front's patches, and the top's nearest blocks lie three cells from its rim points: the top
  // was no candidate there and the front took them (14 here; 13-62 in fresh offices 68-72 of
  // bench/planes_sweep.py at 3 cm, each a false plane touching the top in issue 19's measure).
  // As at a foot (LevelStrips::stripOnUnseenLevel): the rim's points on the top's plane, within its reach,
  // are the top's. The scan as the sweep's offices are scanned (0.25° beams, 0.4° lines).
  std::string scene = test::hallScene(8.3865, 6.8647, 3.058, R"({"x": 5.628, "y": 2.048, "yaw_deg": -162.392}, {"x": 7.008, "y": 4.421, "yaw_deg": 169.189}, {"x": 2.715, "y": 2.312, "yaw_deg": 118.564})",
                                      R"({"class": "other", "classes": {"top": "table"}, "max": [6.2018, 0.45, 0.9508], "min": [3.9242, 0.0, 0.0], "omit": ["bottom", "y-"], "type": "box"})", 0.03);
  const auto finer = [&scene](const std::string& from, const std::string& to) {
    const auto at = scene.find(from);
    REQUIRE(at != std::string::npos);
    scene.replace(at, from.size(), to);
  };
  finer(R"("angular_step_deg": 0.5)", R"("angular_step_deg": 0.25)");
  finer(R"("tilt_step_deg": 1.0)", R"("tilt_step_deg": 0.4)");
  const Scanned scanned(scene, "office72_sideboard.json", 0.0, 0.03);
  const std::vector<std::int32_t> labels = scanned.pointLabels(scanned.labelOptions());
  std::map<std::int32_t, std::int32_t> surface_of = surfaceOfPatches(labels, scanned.truth);
  constexpr std::int32_t kTop = 6, kFront = 9;  // the sideboard's top (it has no bottom) and its y+ face
  std::size_t top = 0, top_on_front = 0;
  for (std::size_t k = 0; k < scanned.points.size(); ++k) {
    if (scanned.truth[k] != kTop) continue;
    ++top;
    top_on_front += labels[k] > 0 && surface_of[labels[k]] == kFront ? 1 : 0;
  }
  MESSAGE(top << " points of the top, " << top_on_front << " on the front's patches");
  REQUIRE(top > 1500);
  CHECK(top_on_front == 0);
}
