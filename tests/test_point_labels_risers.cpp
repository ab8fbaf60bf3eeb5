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
#include "stair_flight.hpp"

using namespace mlmap;

namespace {

using Flight = test::StairFlight;
constexpr int kSteps = Flight::kSteps;

// The flight's points labelled as `mlmap label` labels a cloud without poses: each point's
// patch (by_patch: its truth counts per patch), the planes refitted, and each true surface's
// point count.
struct Labelled {
  std::vector<PointPlane> fitted;
  test::TruthByPatch by_patch;
  std::map<std::int32_t, std::size_t> surface_points;

  explicit Labelled(const Flight& flight) {
    Scan all;
    all.points = flight.points;
    std::vector<std::int32_t> labels = labelPoints(flight.map, all);
    fitted = refinePointLabels(flight.map, flight.detection.planes, flight.points, labels,
                               PointLabelRefinement{.noise = labelNoiseCap(flight.detection, false),
                                                    .band = flight.detection.config.epsilon + 0.5 * flight.map.cellSize()});
    by_patch = test::truthByPatch(labels, flight.truth);
    for (const std::int32_t surface : flight.truth) ++surface_points[surface];
  }
};

}  // namespace

TEST_CASE("Point labels: a riser shorter than two cells is refitted plumb, not leaning onto the treads") {
  // At 10 cm cells each riser's blocks also hold the front and back strips of the treads
  // above and below it: most of the points its patch took lie within the treads'
  // tolerance, and the refit without them was refused as "mostly edge", so the riser's
  // plane kept leaning 10-17 deg onto the treads and took 40 % of each tread (the peers'
  // make_scene.py room at 10 cm: 20 of 23 planes matched at 5 mm of noise, 23 now).
  static const Flight flight(0.005, 0.1);
  const Labelled labelled(flight);
  const auto& [fitted, by_patch, surface_points] = labelled;
  int plumb = 0;
  for (int k = 0; k < kSteps; ++k) {
    const std::int32_t riser = Flight::riser(k);
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
                     << 100.0 * static_cast<double>(best_count) / static_cast<double>(surface_points.at(riser))
                     << " % of it and " << others << " other points");
    // Leaning 10-17° it took 40 % of each tread's ~670 points; capped by the measured σ
    // (labelNoiseCap) the band is too thin to turn one riser of five upright again (7°), but
    // it takes no strip of the treads.
    CHECK(lean_deg < 8.0);
    CHECK(others < 150);
    if (lean_deg < 2.0) ++plumb;
  }
  CHECK(plumb >= 3);
}

TEST_CASE("Point labels: with 1 cm of noise measured, the treads keep their strips by the risers") {
  // The tolerances capped by the 3 cm the build assumed instead of the 1 cm measured: at
  // 10 cm cells the risers' planes, leaning a few degrees, reached into the treads above and
  // below them and took their strips: the upper three treads' IoU with their patches 0.54,
  // 0.60, 0.65 (make_scene.py's rooms with 1 cm of noise at 10 cm cells: 18-19 of 23 planes
  // matched, 22-23 now). The lower two stay below 0.3 either way (a weak spot).
  const Flight flight(0.01, 0.1);
  REQUIRE(flight.detection.stats.prior_noise == doctest::Approx(0.03));  // σ measured, not assumed
  const Labelled labelled(flight);
  const auto& [fitted, by_patch, surface_points] = labelled;
  for (int k = 2; k < kSteps; ++k) {
    const std::int32_t tread = Flight::tread(k);
    double best_iou = 0.0;
    for (const auto& [patch, by_truth] : by_patch) {
      const auto found = by_truth.find(tread);
      if (patch <= 0 || found == by_truth.end()) continue;
      std::size_t patch_points = 0;
      for (const auto& [surface, count] : by_truth) patch_points += count;
      const double both = static_cast<double>(found->second);
      best_iou = std::max(best_iou, both / (static_cast<double>(surface_points.at(tread) + patch_points) - both));
    }
    MESSAGE("tread " << k << ": IoU " << best_iou);
    CHECK(best_iou >= 0.66);
  }
}
