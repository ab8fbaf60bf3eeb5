// Per-point labels: the collecting block's patch, then refined point by point against
// the patches' planes (a block at an edge holds points of two surfaces).
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <string>

#ifdef MLMAP_HAVE_OPENMP
#include <omp.h>
#endif

#include "mlmap/error.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "mlmap/planes/point_labels.hpp"
#include "mlmap/sim/simulator.hpp"
#include "helpers.hpp"
#include "room_scenes.hpp"
#include "scanned_scene.hpp"

using namespace mlmap;

namespace {

using test::Scanned;
using test::boxRoomScene;
using test::surfaceOfPatches;

// A floor (z = 0) meeting a wall at x = 1.98, i.e. inside the cells 1.95–2.00 m at
// 5 cm: those cells' floor points join the wall's vertical blocks. The scan holds
// every point the map was built from.
struct Corner {
  MLMap map{0.05};
  Scan scan;
  PlaneDetection detection;
  std::int32_t floor_id = 0;
  std::int32_t wall_id = 0;

  Corner() {
    std::mt19937 random(7);
    std::normal_distribution<double> noise(0.0, 0.003);
    for (int a = 0; a < 198; ++a)
      for (int b = 0; b <= 200; ++b) scan.points.emplace_back(0.01 * a, 0.01 * b, noise(random));
    for (int b = 0; b <= 200; ++b)
      for (int c = 0; c <= 150; ++c) scan.points.emplace_back(1.98 + noise(random), 0.01 * b, 0.01 * c);
    for (const Point& p : scan.points) map.insert(p, 1e-4);
    detection = detectPlanes(map);
    for (const Plane& plane : detection.planes) {
      if (plane.label == PlaneClass::Floor) floor_id = plane.id;
      if (plane.label == PlaneClass::Wall) wall_id = plane.id;
    }
  }

  PointLabelRefinement options() const {
    return PointLabelRefinement{.band = detection.config.epsilon + 0.5 * map.cellSize()};
  }
};

// A cabinet against a wall and a crate on the floor, scanned from three poses with 1 cm
// of range noise: simulated and detected once for the tests that use it.
const Scanned& cabinetRoom() {
  static const Scanned scanned(
      boxRoomScene(R"({"x": 2.5, "y": 2.0, "yaw_deg": 150}, {"x": 3.5, "y": 3.2, "yaw_deg": 200},
                      {"x": 2.0, "y": 3.5, "yaw_deg": -90})",
                   R"({"type": "box", "class": "other", "min": [0, 1.0, 0], "max": [0.5, 3.0, 1.8], "omit": ["bottom", "x-"]},
      {"type": "box", "class": "other", "min": [4.0, 1.0, 0], "max": [4.6, 1.5, 0.5], "omit": ["bottom"]})"),
      "cabinet.json");
  return scanned;
}

}  // namespace

TEST_CASE("Point labels: floor points in the wall's corner blocks leave the wall for the floor") {
  Corner corner;
  REQUIRE(corner.floor_id > 0);
  REQUIRE(corner.wall_id > 0);
  const Scan& scan = corner.scan;
  std::vector<std::int32_t> labels = labelPoints(corner.map, scan);
  // The situation this pass exists for: the block rule gives the corner cells' floor
  // points (x 1.95–1.97 m, 1–3 cm off the wall) to the wall.
  const auto corner_floor = [&scan](std::size_t k) {
    return scan.points[k].x() >= 1.95 && scan.points[k].x() < 1.965 && std::abs(scan.points[k].z()) < 0.01;
  };
  int corner_floor_points = 0;
  int on_the_wall_before = 0;
  for (std::size_t k = 0; k < scan.size(); ++k) {
    if (!corner_floor(k)) continue;
    ++corner_floor_points;
    on_the_wall_before += labels[k] == corner.wall_id;
  }
  REQUIRE(corner_floor_points > 300);
  REQUIRE(on_the_wall_before > corner_floor_points * 9 / 10);

  const auto planes = refinePointLabels(corner.map, corner.detection.planes, scan.points, labels, corner.options());
  int floor_after = 0;
  int wall_points = 0;
  int wall_points_on_the_wall = 0;
  for (std::size_t k = 0; k < scan.size(); ++k) {
    if (corner_floor(k)) floor_after += labels[k] == corner.floor_id;
    if (scan.points[k].z() > 0.05 && scan.points[k].x() > 1.9) {
      ++wall_points;
      wall_points_on_the_wall += labels[k] == corner.wall_id;
    }
  }
  CHECK(floor_after > corner_floor_points * 99 / 100);
  CHECK(wall_points_on_the_wall > wall_points * 99 / 100);
  // The refitted planes are the true ones, tolerance a few noise σ.
  const auto byId = [&planes](std::int32_t id) {
    return *std::find_if(planes.begin(), planes.end(), [id](const PointPlane& plane) { return plane.id == id; });
  };
  REQUIRE(planes.size() == corner.detection.planes.size());
  const PointPlane floor = byId(corner.floor_id);
  CHECK(std::abs(floor.normal.z()) > std::cos(0.2 * M_PI / 180.0));
  CHECK(std::abs(floor.offset) < 0.002);
  CHECK(floor.tolerance < 0.02);
  const PointPlane wall = byId(corner.wall_id);
  CHECK(std::abs(wall.normal.x()) > std::cos(0.2 * M_PI / 180.0));
  CHECK(std::abs(std::abs(wall.offset) - 1.98) < 0.002);
}

TEST_CASE("Point labels: a point on no patch's plane gets none, and a point beside a patch gets it") {
  Corner corner;
  Scan scan;
  scan.points = {Point(1.0, 1.0, 0.04),     // 4 cm above the floor: its block collects it, its plane does not
                 Point(1.0, 1.0, 0.001),    // on the floor
                 Point(5.0, 5.0, 0.0)};     // beyond the map
  std::vector<std::int32_t> labels = labelPoints(corner.map, scan);
  CHECK(labels[0] == corner.floor_id);
  refinePointLabels(corner.map, corner.detection.planes, scan.points, labels, corner.options());
  CHECK(labels[0] == 0);
  CHECK(labels[1] == corner.floor_id);
  CHECK(labels[2] == -1);
}

TEST_CASE("Point labels: non-finite points beside a patch's points get none, with beams too") {
  Corner corner;
  std::vector<Point> points = corner.scan.points;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  points.emplace_back(1.0, 1.0, nan);
  points.emplace_back(nan, 1.0, 0.0);
  points.emplace_back(1.0, 1.0, inf);
  Scan all;
  all.points = points;
  std::vector<std::int32_t> labels = labelPoints(corner.map, all);
  // As if their blocks had collected them: the refinement must not trust that.
  for (std::size_t k = points.size() - 3; k < points.size(); ++k) labels[k] = corner.floor_id;
  const std::vector<Point> origins{Point(1.0, 1.0, 1.2)};
  const std::vector<std::uint32_t> origin_of_point(points.size(), 0);
  refinePointLabels(corner.map, corner.detection.planes, points, labels, corner.options(),
                    BeamOrigins{origins, origin_of_point});
  for (std::size_t k = points.size() - 3; k < points.size(); ++k) CHECK(labels[k] <= 0);
  CHECK(std::count(labels.begin(), labels.end(), corner.floor_id) > 30000);
}

TEST_CASE("Point labels: patch ids the plane list does not know, and a hostile plane list, give none") {
  Corner corner;
  const Scan& scan = corner.scan;
  std::vector<Plane> planes = corner.detection.planes;
  for (Plane& plane : planes) plane.id += 1000;  // no block carries these ids
  planes.push_back(Plane{});
  planes.back().id = -5;
  planes.back().normal = Eigen::Vector3d::Zero();
  planes.back().offset = std::nan("");
  planes.push_back(planes.front());  // a repeated id
  planes.push_back(Plane{});
  planes.back().id = std::numeric_limits<std::int32_t>::max();  // sized nothing by it
  std::vector<std::int32_t> labels = labelPoints(corner.map, scan);
  refinePointLabels(corner.map, planes, scan.points, labels);
  for (const std::int32_t label : labels) CHECK(label <= 0);
}

#ifdef MLMAP_HAVE_OPENMP
TEST_CASE("Point labels: the refinement gives the same labels at 1 and 2 threads") {
  Corner corner;
  const Scan& scan = corner.scan;
  std::vector<std::vector<std::int32_t>> runs;
  const int threads = omp_get_max_threads();
  for (const int count : {1, 2}) {
    omp_set_num_threads(count);
    std::vector<std::int32_t> labels = labelPoints(corner.map, scan);
    refinePointLabels(corner.map, corner.detection.planes, scan.points, labels, corner.options());
    runs.push_back(labels);
  }
  omp_set_num_threads(threads);
  CHECK(runs[0] == runs[1]);
}
#endif

TEST_CASE("Point labels: with the beams' origins, fewer points at edges take the other surface's patch") {
  // Four scans of a room with a table and two boxes, 1 cm range noise along each beam.
  // A point near an edge lies within noise of two planes; the likelier one is the plane
  // its beam meets nearer the measured range, and that depends on the point's own beam:
  // the same wall is seen head on from one pose and grazing from another.
  // Scanned twice as finely as the shared scene, for enough points at every edge.
  std::string scene_json = test::kRoomsJson;
  scene_json.replace(scene_json.find("\"angular_step_deg\": 1.0"), 23, "\"angular_step_deg\": 0.5");
  scene_json.replace(scene_json.find("\"tilt_step_deg\": 2.0"), 20, "\"tilt_step_deg\": 1.0");
  const Scanned room(scene_json, "rooms.json");
  const std::vector<Point>& points = room.points;
  const std::vector<std::int32_t>& truth = room.truth;
  std::vector<std::int32_t> by_spread = room.blockLabels();
  refinePointLabels(room.map, room.detection.planes, points, by_spread, room.options());
  std::vector<std::int32_t> by_beam = room.blockLabels();
  refinePointLabels(room.map, room.detection.planes, points, by_beam, room.options(), room.beams());
  // Points on a patch that is mostly another surface's.
  const std::size_t wrong_by_spread = test::labelAgreement(by_spread, truth).misplaced();
  const std::size_t wrong_by_beam = test::labelAgreement(by_beam, truth).misplaced();
  MESSAGE(points.size() << " points; on another surface's patch: " << wrong_by_spread << " ranked by spread, "
                        << wrong_by_beam << " by beam");
  REQUIRE(wrong_by_spread > 100);
  CHECK(wrong_by_beam * 5 < wrong_by_spread * 4);
}

TEST_CASE("Point labels: beam origins must name one origin per point") {
  Corner corner;
  std::vector<std::int32_t> labels = labelPoints(corner.map, corner.scan);
  const std::vector<Point> origins{Point::Zero()};
  const std::vector<std::uint32_t> too_few(3, 0);
  CHECK_THROWS_AS(refinePointLabels(corner.map, corner.detection.planes, corner.scan.points, labels, corner.options(),
                                    BeamOrigins{origins, too_few}),
                  Error);
  std::vector<std::uint32_t> out_of_range(corner.scan.size(), 0);
  out_of_range.back() = 1;
  CHECK_THROWS_AS(refinePointLabels(corner.map, corner.detection.planes, corner.scan.points, labels, corner.options(),
                                    BeamOrigins{origins, out_of_range}),
                  Error);
}

TEST_CASE("Point labels: at the foot of a cabinet and above its side, the floor's and the wall's points stay theirs") {
  // A cabinet against a wall and a crate on the floor, scanned from three poses with 1 cm
  // of range noise. Points where they meet the floor or the wall lie within noise of both
  // planes and go to the larger patch; a plane is only where its patch is (above the
  // cabinet its side's plane is air).
  const Scanned& scanned = cabinetRoom();
  const std::vector<Point>& points = scanned.points;
  const std::vector<std::int32_t>& truth = scanned.truth;
  const std::vector<std::int32_t> labels = scanned.pointLabels(scanned.options());
  std::map<std::int32_t, std::int32_t> surface_of = surfaceOfPatches(labels, truth);
  // The room's own surfaces are planes 0-5; their points on a patch of the furniture's.
  std::size_t room = 0, taken = 0, swapped = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (truth[k] < 0 || truth[k] > 5) continue;
    ++room;
    if (labels[k] <= 0 || surface_of[labels[k]] == truth[k]) continue;
    ++(surface_of[labels[k]] > 5 ? taken : swapped);
  }
  MESSAGE(room << " points on the room's surfaces: " << taken << " on the furniture's patches, " << swapped
               << " on another of the room's");
  REQUIRE(room > 100000);
  // Under 0.01 %: 61 by distance alone, 42 by the beam's geometry, 24 with edge ties to
  // the larger patch, now 10 (the surface's noise tail past its plane, behindEdge).
  CHECK(taken * 10000 < room);
  // The strips where the room's own surfaces meet (a wall's foot) go to the larger one:
  // 515 points here, 78 when the beam's geometry decided and 309 by distance alone.
  CHECK(swapped * 200 < room);  // under 0.5 %
}

TEST_CASE("Point labels: a crate's patches end at the floor and the wall they stand on, with or without beams") {
  // Crates on the floor, one against a wall, scanned from three poses with 1 cm of range
  // noise. Along each edge where a crate meets the floor or the wall a strip of points lies
  // within noise of both planes; it goes to the larger patch, the floor's or the wall's, so
  // that no crate's patch holds a point of them (a patch precision at point IoU counts every
  // such patch against the detection, however few of the floor's points it holds).
  const Scanned scanned(
      boxRoomScene(R"({"x": 3.0, "y": 2.5, "yaw_deg": 20}, {"x": 4.5, "y": 1.5, "yaw_deg": 160},
                      {"x": 1.5, "y": 3.5, "yaw_deg": -60})",
                   R"({"type": "box", "class": "other", "min": [1.0, 1.0, 0], "max": [1.6, 1.5, 0.5], "omit": ["bottom"]},
      {"type": "box", "class": "other", "min": [4.2, 3.4, 0], "max": [4.9, 4.0, 0.6], "omit": ["bottom"]},
      {"type": "box", "class": "other", "min": [2.4, 4.4, 0], "max": [3.2, 5.0, 0.7], "omit": ["bottom", "y+"]},
      {"type": "box", "class": "other", "min": [5.3, 0.8, 0], "max": [6.0, 1.6, 0.9], "omit": ["bottom", "x+"]})"),
      "crates.json");
  for (const bool with_beams : {true, false}) {
    CAPTURE(with_beams);
    std::vector<std::int32_t> labels = scanned.blockLabels();
    refinePointLabels(scanned.map, scanned.detection.planes, scanned.points, labels, scanned.options(),
                      with_beams ? scanned.beams() : BeamOrigins{});
    std::size_t crate_patches = 0, touching = 0, room_points_taken = 0;
    for (const auto& [patch, by_truth] : test::truthByPatch(labels, scanned.truth)) {
      if (test::majorityTruth(by_truth) <= 5) continue;  // the room's surfaces are planes 0-5
      ++crate_patches;
      std::size_t room = 0;
      for (const auto& [surface, n] : by_truth) room += surface >= 0 && surface <= 5 ? n : 0;
      touching += room > 0 ? 1 : 0;
      room_points_taken += room;
    }
    MESSAGE(crate_patches << " crate patches, " << touching << " holding " << room_points_taken
                          << " points of the floor or the walls");
    REQUIRE(crate_patches >= 8);
    CHECK(touching * 6 <= crate_patches);  // 7 and 8 of 12 when the beam's geometry decided edges
  }
}

TEST_CASE("Point labels: floor points behind a face on a cell boundary, two cells from the floor's blocks, go to the floor") {
  // A box's face at x = 2.00 (a cell boundary at 5 cm) stands on the floor, which runs
  // from it to x = 4. The face's points fill both columns beside the boundary, so the
  // floor's strip in them joins the face's vertical blocks; floor points that range noise
  // put just behind the face (x 1.99-2.00) lie two cells from the floor's nearest own block.
  // They went to the face, which then touched the floor (issue 19's held-out measure).
  MLMap map(0.05);
  Scan scan;
  std::mt19937 random(11);
  std::normal_distribution<double> noise(0.0, 0.003);
  for (int a = 0; a <= 402; ++a)
    for (int b = 0; b <= 200; ++b) scan.points.emplace_back(1.99 + 0.005 * a, 0.01 * b, noise(random));
  for (int b = 0; b <= 200; ++b)
    for (int c = 1; c <= 150; ++c) scan.points.emplace_back(2.0 + noise(random), 0.01 * b, 0.01 * c);
  for (const Point& p : scan.points) map.insert(p, 1e-4);
  const PlaneDetection detection = detectPlanes(map);
  std::int32_t floor_id = 0;
  for (const Plane& plane : detection.planes)
    if (plane.label == PlaneClass::Floor) floor_id = plane.id;
  REQUIRE(floor_id > 0);
  std::vector<std::int32_t> labels = labelPoints(map, scan);
  refinePointLabels(map, detection.planes, scan.points, labels,
                    PointLabelRefinement{.band = detection.config.epsilon + 0.5 * map.cellSize()});
  int behind = 0;
  int on_floor = 0;
  for (std::size_t k = 0; k < scan.size(); ++k) {
    const Point& p = scan.points[k];
    if (p.x() >= 2.0 || std::abs(p.z()) > 0.006 || p.y() < 0.1 || p.y() > 1.9) continue;
    ++behind;
    on_floor += labels[k] == floor_id;
  }
  REQUIRE(behind > 300);
  CHECK(on_floor > behind * 95 / 100);
}

TEST_CASE("Point labels: a room surface's points past its plane from the scanner stay off the patches ending there") {
  // A cabinet against a wall and a crate on the floor, 1 cm of range noise. A room
  // surface's noise tail reaches past its plane (from the scanner) beyond its tolerance
  // (3 σ); a point there near the plane of a cabinet's side or a crate's face lay on that
  // patch alone and went to it, which then touched the wall or the floor (issue 19's
  // held-out measure: the simulated lab at 10 cm, 2 of its 11 false patches). Nothing
  // but the surface itself lies past it: the furniture's patches end there.
  const Scanned& scanned = cabinetRoom();
  const std::vector<std::int32_t> labels = scanned.pointLabels(scanned.options());
  std::map<std::int32_t, std::int32_t> surface_of = surfaceOfPatches(labels, scanned.truth);
  // The room's surfaces (true planes 0-5) are axis-aligned: floor z = 0, ceiling z = 2.8,
  // walls x = 0 and 6, y = 0 and 5.
  const auto pastOwnPlane = [&](std::size_t k) {
    const Point& p = scanned.points[k];
    const Point& scanner = scanned.scanners[scanned.scanner_of_point[k]];
    for (const auto& [axis, at] : {std::pair{2, 0.0}, {2, 2.8}, {0, 0.0}, {0, 6.0}, {1, 0.0}, {1, 5.0}})
      if (std::abs(p[axis] - at) < 0.08) return (p[axis] - at) * (scanner[axis] - at) < 0.0;
    return false;
  };
  std::size_t past = 0, on_furniture = 0;
  for (std::size_t k = 0; k < scanned.points.size(); ++k) {
    if (scanned.truth[k] < 0 || scanned.truth[k] > 5 || !pastOwnPlane(k)) continue;
    ++past;
    on_furniture += labels[k] > 0 && surface_of[labels[k]] > 5 ? 1 : 0;
  }
  MESSAGE(past << " points of the room's surfaces past their plane, " << on_furniture << " on the furniture's patches");
  REQUIRE(past > 10000);
  CHECK(on_furniture == 0);
}

TEST_CASE("Point labels: a box's faces are refitted without the points at its edges") {
  // A bench 0.45 m high and 0.4 m deep against the wall x = 0, seen from 2 m. The blocks
  // along an edge hold both faces' points, and the refit on the blocks' points near the
  // plane kept them: the top leaned 1.2 deg towards the front and lay 4 mm off at their
  // edge, the front 0.4 deg. A leaning plane puts the other face's points by the edge
  // within its tolerance (the simulated corridor's bench: single points of the floor or
  // its top on the front's patch, issue 19's held-out measure).
  static const Scanned scanned(
      boxRoomScene(R"({"x": 2.2, "y": 1.2, "yaw_deg": 150}, {"x": 2.4, "y": 3.8, "yaw_deg": 210})",
                   R"({"type": "box", "class": "other", "min": [0, 1.5, 0], "max": [0.4, 3.5, 0.45], "omit": ["bottom", "x-"]})"),
      "bench.json");
  std::vector<std::int32_t> labels = scanned.blockLabels();
  const std::vector<PointPlane> fitted =
      refinePointLabels(scanned.map, scanned.detection.planes, scanned.points, labels, scanned.options(), scanned.beams());
  std::map<std::int32_t, std::int32_t> surface_of = surfaceOfPatches(labels, scanned.truth);
  // True planes: 0-5 the room, 6 the top (z = 0.45), 7 the front (x = 0.4).
  const auto fitOf = [&](std::int32_t surface) -> const PointPlane* {
    for (const PointPlane& plane : fitted)
      if (surface_of.count(plane.id) && surface_of[plane.id] == surface) return &plane;
    return nullptr;
  };
  const PointPlane* top = fitOf(6);
  const PointPlane* front = fitOf(7);
  REQUIRE(top != nullptr);
  REQUIRE(front != nullptr);
  // Where the two faces meet, (0.4, 2.5, 0.45): each plane within 3 mm of it, and within
  // 0.3 deg of its true direction.
  const Point edge(0.4, 2.5, 0.45);
  MESSAGE("top " << top->normal.transpose() << " at the edge " << top->normal.dot(edge) + top->offset << "; front "
                 << front->normal.transpose() << " at the edge " << front->normal.dot(edge) + front->offset);
  CHECK(std::abs(top->normal.dot(edge) + top->offset) < 0.003);
  CHECK(std::abs(front->normal.dot(edge) + front->offset) < 0.003);
  CHECK(std::abs(top->normal.z()) > std::cos(0.3 * M_PI / 180.0));
  CHECK(std::abs(front->normal.x()) > std::cos(0.3 * M_PI / 180.0));
}
