// Per-point labels on a flight of stairs sampled evenly (as the peers' make_scene.py
// samples its room: no scanner, no beams), where a riser is shorter than two cells.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "mlmap/planes/ermsm.hpp"
#include "mlmap/planes/point_labels.hpp"
#include "helpers.hpp"

using namespace mlmap;

namespace {

constexpr int kSteps = 5;
constexpr double kRise = 0.17, kRun = 0.28, kWidth = 1.2, kStart = 2.013, kSide = 0.027;

// A floor and a flight of five steps up along +x, sampled as make_scene.py samples (uniform,
// 5 mm of noise on each axis): truth 0 the floor, 1-5 the treads, 6-10 the risers, 11 the open side, 12 and 13 walls.
// Neither the steps nor the sides lie on cell boundaries (as there: shifted 1.3 and 2.7 cm).
struct Flight {
  std::vector<Point> points;
  std::vector<std::int32_t> truth;
  MLMap map{0.1};
  PlaneDetection detection;

  Flight() {
    std::mt19937 random(11);
    std::normal_distribution<double> noise(0.0, 0.005);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    // Uniform samples of a rectangle at 2,000 points per m² (make_scene.py's default
    // room holds 500,000 points on ~270 m²): `corner` and two edge vectors.
    const auto rectangle = [&](const Point& corner, const Point& u, const Point& v, std::int32_t surface) {
      const auto count = static_cast<int>(2000.0 * u.norm() * v.norm());
      for (int k = 0; k < count; ++k) {
        points.push_back(corner + unit(random) * u + unit(random) * v + Point(noise(random), noise(random), noise(random)));
        truth.push_back(surface);
      }
    };
    const double end = kStart + kSteps * kRun;
    rectangle(Point(0, kSide, 0), Point(kStart, 0, 0), Point(0, kWidth, 0), 0);
    for (int k = 0; k < kSteps; ++k) {
      const double front = kStart + k * kRun;
      rectangle(Point(front, kSide, (k + 1) * kRise), Point(kRun, 0, 0), Point(0, kWidth, 0), 1 + k);
      rectangle(Point(front, kSide, k * kRise), Point(0, 0, kRise), Point(0, kWidth, 0), 1 + kSteps + k);
      // The flight's open side, a staircase outline: a column per step.
      rectangle(Point(front, kSide, 0), Point(kRun, 0, 0), Point(0, 0, (k + 1) * kRise), 11);
    }
    // The walls it stands against: behind its top and along its closed side.
    rectangle(Point(end, kSide, 0), Point(0, kWidth, 0), Point(0, 0, 2.5), 12);
    rectangle(Point(0, kSide + kWidth, 0), Point(end, 0, 0), Point(0, 0, 2.5), 13);
    // As `mlmap build` maps points that carry no variance: the UTM-30LX's 3 cm.
    for (const Point& p : points) map.insert(p, 0.03 * 0.03);
    detection = detectPlanes(map);
  }
};

}  // namespace

TEST_CASE("Point labels: a riser shorter than two cells is refitted plumb, not leaning onto the treads") {
  // At 10 cm cells each riser's blocks also hold the front and back strips of the treads
  // above and below it: most of the points its patch took lie within the treads'
  // tolerance, and the refit without them was refused as "mostly edge", so the riser's
  // plane kept leaning 10-17 deg onto the treads and took 40 % of each tread (the peers'
  // make_scene.py room at 10 cm: 20 of 23 planes matched at 5 mm of noise, 23 now).
  static const Flight flight;
  Scan all;
  all.points = flight.points;
  std::vector<std::int32_t> labels = labelPoints(flight.map, all);
  const std::vector<PointPlane> fitted =
      refinePointLabels(flight.map, flight.detection.planes, flight.points, labels,
                        // As `mlmap label` caps the tolerances: by the larger of the measured
                        // and the assumed noise.
                        PointLabelRefinement{.noise = std::max(flight.detection.config.noise,
                                                               flight.detection.stats.prior_noise),
                                             .band = flight.detection.config.epsilon + 0.5 * flight.map.cellSize()});
  const test::TruthByPatch by_patch = test::truthByPatch(labels, flight.truth);
  std::map<std::int32_t, std::size_t> surface_points;
  for (const std::int32_t surface : flight.truth) ++surface_points[surface];
  int plumb = 0;
  for (int k = 0; k < kSteps; ++k) {
    const std::int32_t riser = 1 + kSteps + k;
    // The patch holding most of the riser's points.
    std::int32_t best = 0;
    std::size_t best_count = 0;
    for (const auto& [patch, by_truth] : by_patch) {
      const auto found = by_truth.find(riser);
      if (found != by_truth.end() && found->second > best_count) {
        best = patch;
        best_count = found->second;
      }
    }
    REQUIRE(best > 0);
    const PointPlane* plane = nullptr;
    for (const PointPlane& candidate : fitted)
      if (candidate.id == best) plane = &candidate;
    REQUIRE(plane != nullptr);
    const double lean_deg = std::acos(std::min(1.0, std::abs(plane->normal.x()))) * 180.0 / M_PI;
    // What the patch holds besides the riser: the treads' strips a leaning plane takes.
    std::size_t others = 0;
    for (const auto& [surface, count] : by_patch.at(best))
      if (surface != riser) others += count;
    MESSAGE("riser " << k << ": patch " << best << " leans " << lean_deg << " deg, holds "
                     << 100.0 * static_cast<double>(best_count) / static_cast<double>(surface_points[riser])
                     << " % of it and " << others << " other points");
    CHECK(lean_deg < 5.0);
    if (lean_deg < 2.0) ++plumb;
  }
  CHECK(plumb >= 4);
}
