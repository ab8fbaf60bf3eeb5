// Per-point labels at a room's corners: a wall's top under a ceiling and its foot on the
// floor, both surfaces larger than the wall (PCL's room_scan2 at 5 cm: 122 of a wall's
// 2,226 points, some 0.4 cm from its plane and 6 cm from the ceiling's, went to the
// ceiling because the larger patch took every point within both planes' tolerances).
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <random>
#include <utility>

#include "mlmap/planes/ermsm.hpp"
#include "mlmap/planes/point_labels.hpp"

using namespace mlmap;

namespace {

// Points measured from scanners with 1 cm of range noise along each beam, each with the
// surface (a small integer) it was measured on; the planes detected on their map, and
// every point labelled with its scanner's beam.
struct Scanned {
  MLMap map;
  std::vector<Point> points;
  std::vector<std::uint8_t> truth;
  std::vector<Point> scanners;
  std::vector<std::uint32_t> scanner_of_point;
  PlaneDetection detection;
  std::mt19937 random;
  std::normal_distribution<double> range_noise{0.0, 0.01};

  Scanned(double cell, std::vector<Point> from, unsigned seed) : map(cell), scanners(std::move(from)), random(seed) {}

  // The return of a beam from `scanner` to a point on a surface.
  void add(std::uint32_t scanner, const Point& on_surface, std::uint8_t surface) {
    const Eigen::Vector3d ray = on_surface - scanners[scanner];
    const double range = ray.norm() + range_noise(random);
    points.push_back(scanners[scanner] + range * ray.normalized());
    truth.push_back(surface);
    scanner_of_point.push_back(scanner);
  }

  void detect() {
    for (const Point& p : points) map.insert(p, 1e-4);
    detection = detectPlanes(map);
  }

  std::vector<std::int32_t> labels() const {
    Scan scan;
    scan.points = points;
    std::vector<std::int32_t> labels = labelPoints(map, scan);
    refinePointLabels(map, detection.planes, points, labels,
                      PointLabelRefinement{.noise = detection.config.noise,
                                           .band = detection.config.epsilon + 0.5 * map.cellSize()},
                      BeamOrigins{scanners, scanner_of_point});
    return labels;
  }

  // The patch holding most of a surface's points (0: none).
  std::int32_t patchOf(const std::vector<std::int32_t>& labels, std::uint8_t surface) const {
    std::map<std::int32_t, std::size_t> count;
    for (std::size_t k = 0; k < labels.size(); ++k)
      if (truth[k] == surface && labels[k] > 0) ++count[labels[k]];
    std::int32_t best = 0;
    for (const auto& [id, n] : count)
      if (best == 0 || n > count[best]) best = id;
    return best;
  }

  // The patches holding most of surfaces `a` and `b`: both found, and apart.
  std::pair<std::int32_t, std::int32_t> twoPatchesOf(const std::vector<std::int32_t>& labels, std::uint8_t a,
                                                     std::uint8_t b) const {
    const std::int32_t first = patchOf(labels, a), second = patchOf(labels, b);
    REQUIRE(first > 0);
    REQUIRE(second > 0);
    REQUIRE(first != second);
    return {first, second};
  }

  // Of a surface's points k that `pick(k)` takes, the share that carry `id`, and how many
  // were taken.
  template <typename Pick>
  std::pair<double, std::size_t> shareOn(const std::vector<std::int32_t>& labels, std::uint8_t surface,
                                         std::int32_t id, Pick&& pick) const {
    std::size_t all = 0, on = 0;
    for (std::size_t k = 0; k < labels.size(); ++k) {
      if (truth[k] != surface || !pick(k)) continue;
      ++all;
      on += labels[k] == id ? 1 : 0;
    }
    return {all == 0 ? 0.0 : static_cast<double>(on) / static_cast<double>(all), all};
  }
};

enum Surface : std::uint8_t { kFloor, kCeiling, kWall };

// A 4 x 4 m room, 2.6 m high, closed by one wall at x = 4, seen from (2, 2, 1.2); the floor
// and the ceiling sampled more densely than the wall (a scanner's points crowd on the
// surfaces near it), mapped at 5 cm.
struct Room : Scanned {
  static constexpr double kHeight = 2.6;
  static constexpr double kWallX = 4.0;

  Room() : Scanned(0.05, {Point(2.0, 2.0, 1.2)}, 5) {
    for (double x = 0.0075; x < kWallX; x += 0.015)
      for (double y = 0.0075; y < 4.0; y += 0.015) {
        add(0, Point(x, y, 0.0), kFloor);
        add(0, Point(x, y, kHeight), kCeiling);
      }
    for (double y = 0.01; y < 4.0; y += 0.02)
      for (double z = 0.01; z < kHeight; z += 0.02) add(0, Point(kWallX, y, z), kWall);
    detect();
  }
};

}  // namespace

TEST_CASE("Point labels: a wall keeps its top under a larger ceiling and its foot on a larger floor") {
  const Room room;
  const std::vector<std::int32_t> labels = room.labels();
  const std::int32_t floor = room.patchOf(labels, kFloor), ceiling = room.patchOf(labels, kCeiling),
                     wall = room.patchOf(labels, kWall);
  REQUIRE(floor > 0);
  REQUIRE(ceiling > 0);
  REQUIRE(wall > 0);
  REQUIRE(floor != ceiling);
  REQUIRE(wall != ceiling);
  REQUIRE(wall != floor);
  // The wall's points within 5 cm of each corner (3 cm is the planes' tolerance: 3 σ).
  const double top =
      room.shareOn(labels, kWall, wall, [&](std::size_t k) { return room.points[k].z() > Room::kHeight - 0.05; }).first;
  const double foot = room.shareOn(labels, kWall, wall, [&](std::size_t k) { return room.points[k].z() < 0.05; }).first;
  // And the ceiling's and the floor's within 5 cm of the wall stay theirs.
  const auto by_wall = [&](std::size_t k) { return room.points[k].x() > Room::kWallX - 0.05; };
  const double ceiling_by_wall = room.shareOn(labels, kCeiling, ceiling, by_wall).first;
  const double floor_by_wall = room.shareOn(labels, kFloor, floor, by_wall).first;
  MESSAGE("wall's top on the wall " << top * 100 << " %, its foot " << foot * 100 << " %; the ceiling by the wall "
                                    << ceiling_by_wall * 100 << " %, the floor " << floor_by_wall * 100 << " %");
  // Before, the larger patch took every point within both tolerances: the wall's top 5 cm
  // and its foot lost about half their points to the ceiling and the floor.
  CHECK(top > 0.9);
  CHECK(foot > 0.9);
  CHECK(ceiling_by_wall > 0.9);
  CHECK(floor_by_wall > 0.9);
}

namespace {

enum Part : std::uint8_t { kTop, kPanel, kGround };

// A table top at z = 0.75 over x 1-2.45 m, y 1-2.2 m, with a panel under it set back 8 cm
// from its front edge (x = 2.37), on a floor, seen from (4, 1.6, 1.4) in front of it with
// 1 cm of range noise, mapped at 10 cm: the top's outline reaches past the panel's plane
// by less than a cell's diagonal and the planes' tolerance (PCL's office1 at 10 cm).
struct Overhang : Scanned {
  static constexpr double kTopZ = 0.75;
  static constexpr double kFront = 2.45;
  static constexpr double kPanelX = 2.37;

  Overhang() : Scanned(0.1, {Point(4.0, 1.6, 1.4)}, 7) {
    // The height at which the beam to `p` passes the top's front edge: below the top, seen.
    const auto underFront = [&](const Point& p) {
      const double t = (scanners[0].x() - kFront) / (scanners[0].x() - p.x());
      return scanners[0].z() + t * (p.z() - scanners[0].z()) < kTopZ;
    };
    for (double x = 1.0075; x < kFront; x += 0.015)
      for (double y = 1.0075; y < 2.2; y += 0.015) add(0, Point(x, y, kTopZ), kTop);
    for (double y = 1.01; y < 2.2; y += 0.02)
      for (double z = 0.01; z < kTopZ; z += 0.02)
        if (underFront(Point(kPanelX, y, z))) add(0, Point(kPanelX, y, z), kPanel);
    for (double x = 0.01; x < 5.0; x += 0.02)
      for (double y = 0.01; y < 3.2; y += 0.02) {
        const bool under_table = x < kFront && y > 1.0 && y < 2.2;
        if (!under_table || (x > kPanelX && underFront(Point(x, y, 0.0)))) add(0, Point(x, y, 0.0), kGround);
      }
    detect();
  }
};

}  // namespace

TEST_CASE("Point labels: a table top keeps its rim over a panel set back under it") {
  const Overhang scene;
  const std::vector<std::int32_t> labels = scene.labels();
  const std::int32_t top = scene.patchOf(labels, kTop);
  REQUIRE(top > 0);
  // The top's points over the panel's plane and up to 5 cm past it (its tolerance is 3).
  const auto [share, rim] = scene.shareOn(labels, kTop, top, [&](std::size_t k) {
    return scene.points[k].x() >= Overhang::kPanelX - 0.01 && scene.points[k].x() <= Overhang::kPanelX + 0.05;
  });
  REQUIRE(rim > 100);
  MESSAGE("the top's points over the panel's plane on the top: " << share * 100 << " % of " << rim);
  // A convex edge: the corner rule must not apply. A version that judged where a patch ends
  // by its outline alone (cell corners: the top "ended" at the panel's plane) gave the panel
  // the top's points within its tolerance: 64.5 % of them on the top.
  CHECK(share > 0.95);
}

namespace {

enum Face : std::uint8_t { kCabinetTop, kNearSide, kFarSide, kCabinetFloor };

// A cabinet 0.6 x 0.5 x 0.9 m on a floor, seen from two scanners at opposite corners, each
// seeing the top and the two sides that face it, with 1 cm of range noise, mapped at 5 cm.
// Each side holds more points than the top.
struct Cabinet : Scanned {
  static constexpr double kX0 = 1.8, kX1 = 2.4, kY0 = 1.8, kY1 = 2.3, kTop = 0.9;

  Cabinet() : Scanned(0.05, {Point(0.5, 0.5, 1.2), Point(3.7, 3.6, 1.2)}, 9) {
    for (std::uint32_t s = 0; s < 2; ++s) {
      const bool near = s == 0;  // scanner 0 sees the sides at x0 and y0, scanner 1 those at x1 and y1
      for (double x = kX0 + 0.0075; x < kX1; x += 0.015)
        for (double y = kY0 + 0.0075; y < kY1; y += 0.015) add(s, Point(x, y, kTop), kCabinetTop);
      for (double z = 0.0075; z < kTop; z += 0.015) {
        for (double x = kX0 + 0.0075; x < kX1; x += 0.015) add(s, Point(x, near ? kY0 : kY1, z), near ? kNearSide : kFarSide);
        for (double y = kY0 + 0.0075; y < kY1; y += 0.015) add(s, Point(near ? kX0 : kX1, y, z), near ? kNearSide : kFarSide);
      }
      for (double x = 0.01; x < 4.2; x += 0.02)
        for (double y = 0.01; y < 4.1; y += 0.02) {
          const bool under = x > kX0 - 0.02 && x < kX1 + 0.02 && y > kY0 - 0.02 && y < kY1 + 0.02;
          const bool behind = near ? (x > kX0 && y > kY0) : (x < kX1 && y < kY1);  // roughly in its shadow
          if (!under && !(behind && std::hypot(x - 2.1, y - 2.05) < 1.0)) add(s, Point(x, y, 0.0), kCabinetFloor);
        }
    }
    detect();
  }
};

}  // namespace

TEST_CASE("Point labels: a cabinet's top by its far edge stays the top's, not a side its scanner cannot see") {
  const Cabinet scene;
  const std::vector<std::int32_t> labels = scene.labels();
  const std::int32_t top = scene.patchOf(labels, kCabinetTop);
  REQUIRE(top > 0);
  // The top's points within 3 cm of the edges far from the scanner that saw them: there
  // the far sides' planes lie within their tolerance too, and those sides are larger.
  const auto [share, far_edge] = scene.shareOn(labels, kCabinetTop, top, [&](std::size_t k) {
    const Point& p = scene.points[k];
    const double to_far_edge = scene.scanner_of_point[k] == 0 ? std::min(Cabinet::kX1 - p.x(), Cabinet::kY1 - p.y())
                                                              : std::min(p.x() - Cabinet::kX0, p.y() - Cabinet::kY0);
    return to_far_edge <= 0.03;
  });
  REQUIRE(far_edge > 100);
  MESSAGE("the top's points by its far edges on the top: " << share * 100 << " % of " << far_edge);
  CHECK(share > 0.95);
}

namespace {

enum RimFace : std::uint8_t { kRimTop, kRimFace, kRimFloor };

// A level top from x0 to x1 and from `front` back by `depth` at `height`, a face flush with its
// front edge down to the floor, and the floor in front of it, seen from `scanner`: the face
// sampled every 1 cm (seen head on), the top every 3 cm (seen at a grazing angle), the floor
// every `floor_step` as far as `floor_x1`, with 1 cm of range noise, mapped at 5 cm.
struct Rim : Scanned {
  struct Shape {
    double x0, x1, front, depth, height, floor_x1;
    double floor_step = 0.02;
  };

  Rim(const Point& scanner, unsigned seed, const Shape& shape) : Scanned(0.05, {scanner}, seed) {
    for (double x = shape.x0 + 0.0075; x < shape.x1; x += 0.03)
      for (double y = shape.front + 0.0075; y < shape.front + shape.depth; y += 0.03)
        add(0, Point(x, y, shape.height), kRimTop);
    for (double x = shape.x0 + 0.005; x < shape.x1; x += 0.01)
      for (double z = 0.005; z < shape.height; z += 0.01) add(0, Point(x, shape.front, z), kRimFace);
    for (double x = 0.01; x < shape.floor_x1; x += shape.floor_step)
      for (double y = 0.01; y < shape.front; y += shape.floor_step) add(0, Point(x, y, 0.0), kRimFloor);
    detect();
  }

  // The share of the face's or the top's points (`surface`) on patch `id`, and their count.
  std::pair<double, std::size_t> shareOf(const std::vector<std::int32_t>& labels, RimFace surface, std::int32_t id) const {
    return shareOn(labels, surface, id, [](std::size_t) { return true; });
  }
};

}  // namespace

TEST_CASE("Point labels: a desk's top keeps its rim over a larger front face flush with it") {
  // A point within both planes' tolerances at the rim went to the larger patch: the front,
  // seen head on, took 74-290 of a generated office desk's top points (bench/planes_sweep.py,
  // offices 51-56), and a face that touches a table top by one point is a false plane in an
  // instance score of the labelled surfaces. A desk 1.2 m wide and 0.6 m deep, its top at
  // 0.75 m (a generated office's desk: a box), seen from 1.3 m in front of it at 1.2 m: the
  // front with ten times the top's points.
  const Rim scene(Point(2.1, 0.3, 1.2), 11, {.x0 = 1.5, .x1 = 2.7, .front = 1.6, .depth = 0.6, .height = 0.75, .floor_x1 = 4.2});
  const std::vector<std::int32_t> labels = scene.labels();
  const auto [top, front] = scene.twoPatchesOf(labels, kRimTop, kRimFace);
  const auto [top_on_front, top_points] = scene.shareOf(labels, kRimTop, front);
  const auto [front_kept, front_points] = scene.shareOf(labels, kRimFace, front);
  MESSAGE("top points on the front's patch: " << top_on_front * top_points << " of " << top_points
                                              << "; front points on it: " << front_kept * 100 << " %");
  CHECK(top_on_front == 0.0);
  // The front gives up no more than the strip within the top's tolerance (3 σ of 75 cm).
  CHECK(front_kept > 0.93);
}

TEST_CASE("Point labels: a riser under a tread's nosing keeps its top strip where it is the larger") {
  // A top keeps its rim over a face below it only where the face reaches further down than a
  // riser: giving every tread the strip of the riser below it (a fifth of a 17 cm riser at
  // 1 cm of noise) lost 9 of bench/stairs_bench.py's 37 steps found. One step, its riser 17 cm
  // tall and its tread 28 cm deep, seen from 1.5 m in front at 0.3 m (bench/stairs_bench.py's
  // low pose): the riser with more points than the tread.
  const Rim scene(Point(1.0, 0.5, 0.3), 13, {.x0 = 0.3, .x1 = 1.7, .front = 2.0, .depth = 0.28, .height = 0.17, .floor_x1 = 2.0});
  const std::vector<std::int32_t> labels = scene.labels();
  const auto [tread, riser] = scene.twoPatchesOf(labels, kRimTop, kRimFace);
  const auto [kept, riser_points] = scene.shareOf(labels, kRimFace, riser);
  const auto [on_tread, all] = scene.shareOf(labels, kRimFace, tread);
  MESSAGE("riser points on its patch: " << kept * 100 << " %, on the tread's: " << on_tread * 100 << " % of " << all);
  CHECK(on_tread < 0.05);
}

TEST_CASE("Point labels: the floor keeps its strip at the foot of a larger cabinet front standing on it") {
  // By size a face seen head on, with more points than the floor seen at a grazing angle, took
  // the floor's points within both planes' tolerances at its foot: a generated office's
  // cabinet front (70,000 points against the floor's 27,000) took 158 of them
  // (bench/planes_sweep.py, office-15), and a face that touches the floor by one point is a
  // false plane in an instance score of the labelled surfaces. A sideboard 2 m wide and 1 m
  // high seen from 2 m in front of it at 1.2 m, the floor every 4 cm: the front with four
  // times the floor's points.
  const Rim scene(Point(2.0, 0.0, 1.2), 17,
                  {.x0 = 1.0, .x1 = 3.0, .front = 2.0, .depth = 0.5, .height = 1.0, .floor_x1 = 4.0, .floor_step = 0.04});
  const std::vector<std::int32_t> labels = scene.labels();
  const auto [floor, front] = scene.twoPatchesOf(labels, kRimFloor, kRimFace);
  // The floor's points within 3 cm (its tolerance, 3 σ) in front of the face.
  const auto at_foot = [&](std::size_t k) { return scene.points[k].y() > 2.0 - 0.03; };
  const auto [foot_on_front, foot_points] = scene.shareOn(labels, kRimFloor, front, at_foot);
  const auto [front_kept, front_points] = scene.shareOf(labels, kRimFace, front);
  MESSAGE("floor points at the foot on the front's patch: " << foot_on_front * foot_points << " of " << foot_points
                                                           << "; front points on it: " << front_kept * 100 << " % of "
                                                           << front_points);
  CHECK(foot_points > 20);
  CHECK(foot_on_front == 0.0);
  // The front gives up no more than the strip within the floor's tolerance (3 σ of 1 m).
  CHECK(front_kept > 0.95);
}

namespace {

enum BackPart : std::uint8_t { kDeskTop, kBackWall, kDeskFloor };

// A desk top at 0.75 m against a wall 4.2 m wide, the wall seen only above the desk's height
// (furniture along it hides its foot), the floor in front, seen from 1.3 m in front of the desk
// at 1.2 m with 1 cm of range noise, mapped at 5 cm.
struct DeskAgainstWall : Scanned {
  DeskAgainstWall() : Scanned(0.05, {Point(2.1, 0.3, 1.2)}, 19) {
    for (double x = 1.5075; x < 2.7; x += 0.03)
      for (double y = 1.6075; y < 2.2; y += 0.03) add(0, Point(x, y, 0.75), kDeskTop);
    for (double x = 0.005; x < 4.2; x += 0.02)
      for (double z = 0.755; z < 2.5; z += 0.02) add(0, Point(x, 2.2, z), kBackWall);
    for (double x = 0.01; x < 4.2; x += 0.03)
      for (double y = 0.01; y < 1.6; y += 0.03) add(0, Point(x, y, 0.0), kDeskFloor);
    detect();
  }
};

}  // namespace

TEST_CASE("Point labels: a wall seen only above a desk against it does not stand on the desk") {
  // A face keeps its foot's strip for the level patch it stands on (the test above), judged by
  // heights and by extent: a wall whose foot is hidden at a desk's height reaches down to the
  // desk's plane like a monitor standing on it, but runs past the desk's ends. By heights alone
  // the desk took the wall's strip at its back edge and touched it (PCL's room_scan2's far wall
  // at 10 cm, two desk-level pieces).
  const DeskAgainstWall scene;
  const std::vector<std::int32_t> labels = scene.labels();
  const auto [desk, wall] = scene.twoPatchesOf(labels, kDeskTop, kBackWall);
  const auto [wall_on_desk, wall_points] = scene.shareOn(labels, kBackWall, desk, [](std::size_t) { return true; });
  MESSAGE("wall points on the desk's patch: " << wall_on_desk * wall_points << " of " << wall_points);
  CHECK(wall_on_desk == 0.0);
}
