// Level surfaces a step apart in one patch (issue 19: "two touching desks whose tops differ
// by 1.7 cm join"): a candidate's slab (ε = 3 σ of range noise) spans the step, and the
// search took both tops as one table. Seen at a glancing angle a top's points lie a few mm
// from it, so the step stands out from block to block: the patch is cut at the seam.
// A surface that is rougher from block to block than its points (registered views a cm
// apart) is not.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "helpers.hpp"
#include "mlmap/io/pcd.hpp"
#include "mlmap/map/ml_map.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "mlmap/planes/point_labels.hpp"
#include "plane_scenes.hpp"
#include "scanned_scene.hpp"

using namespace mlmap;

namespace {

// The patch holding most of true plane `surface`'s points, and the share it holds.
struct Holder {
  std::int32_t patch = 0;
  double share = 0.0;
};
Holder holderOf(const std::vector<std::int32_t>& labels, const std::vector<std::int32_t>& truth, std::int32_t surface) {
  std::map<std::int32_t, std::size_t> by_patch;
  std::size_t points = 0;
  for (std::size_t k = 0; k < labels.size(); ++k) {
    if (truth[k] != surface) continue;
    ++points;
    if (labels[k] > 0) ++by_patch[labels[k]];
  }
  Holder holder;
  for (const auto& [patch, count] : by_patch) {
    const double share = static_cast<double>(count) / static_cast<double>(points);
    if (share > holder.share) holder = {patch, share};
  }
  return holder;
}

// The true plane most points within 5 mm of height `z` and x in (x0, x1) lie on.
std::int32_t surfaceAt(const test::Scanned& scanned, double z, double x0, double x1) {
  std::map<std::int32_t, std::size_t> counts;
  for (std::size_t k = 0; k < scanned.points.size(); ++k) {
    const Point& p = scanned.points[k];
    if (std::abs(p.z() - z) < 0.005 && p.x() > x0 && p.x() < x1) ++counts[scanned.truth[k]];
  }
  std::int32_t best = -1;
  std::size_t most = 0;
  for (const auto& [surface, count] : counts) {
    if (count > most) {
      best = surface;
      most = count;
    }
  }
  return best;
}

// A cloud of world points mapped at `cell`, its planes detected and its points labelled:
// how many lie in the region `inside` marks, and how many of those on its largest patch.
struct RegionOnPatches {
  std::size_t points = 0;
  std::size_t on_largest = 0;
};
template <typename Inside>
RegionOnPatches regionOnPatches(const Scan& cloud, double cell, Inside&& inside) {
  MLMap map(cell);
  for (std::size_t k = 0; k < cloud.size(); ++k) map.insert(cloud.worldPoint(k), cloud.variance(k));
  detectPlanes(map);
  const std::vector<std::int32_t> labels = labelPoints(map, cloud);
  std::map<std::int32_t, std::size_t> by_patch;
  RegionOnPatches region;
  for (std::size_t k = 0; k < cloud.size(); ++k) {
    if (!inside(cloud.worldPoint(k))) continue;
    ++region.points;
    if (labels[k] > 0) ++by_patch[labels[k]];
  }
  for (const auto& [patch, count] : by_patch) region.on_largest = std::max(region.on_largest, count);
  return region;
}

}  // namespace

TEST_CASE("Seams: two touching desks whose tops differ by 2 cm, scanned with 1 cm of range noise, are two patches") {
  // Desk tops at 0.75 and 0.73 m, 1.4 x 0.75 m each, side by side; three scanner poses.
  const std::string furniture =
      R"({"type": "box", "class": "other", "min": [1.5, 2.0, 0.72], "max": [2.9, 2.75, 0.75], "omit": ["bottom"]},
      {"type": "box", "class": "other", "min": [2.9, 2.0, 0.70], "max": [4.3, 2.75, 0.73], "omit": ["bottom"]})";
  const std::string poses =
      R"({"x": 1.0, "y": 1.0, "yaw_deg": 30}, {"x": 5.0, "y": 4.0, "yaw_deg": 210},
      {"x": 3.0, "y": 4.2, "yaw_deg": -90})";
  for (const double turn : {0.0, 10.0}) {
    CAPTURE(turn);
    const test::Scanned scanned(test::boxRoomScene(poses, furniture), "touching_desks.json", turn);
    // Turned about z, the desks' x spans turn too: find each top near the middle of its own.
    const double c = std::cos(turn * M_PI / 180.0), s = std::sin(turn * M_PI / 180.0);
    const auto x_of = [&](double x, double y) { return c * x - s * y; };
    const std::int32_t high = surfaceAt(scanned, 0.75, x_of(1.9, 2.4) - 0.3, x_of(1.9, 2.4) + 0.3);
    const std::int32_t low = surfaceAt(scanned, 0.73, x_of(3.9, 2.4) - 0.3, x_of(3.9, 2.4) + 0.3);
    REQUIRE(high >= 0);
    REQUIRE(low >= 0);
    REQUIRE(high != low);
    const std::vector<std::int32_t> labels = scanned.blockLabels();
    const Holder on_high = holderOf(labels, scanned.truth, high);
    const Holder on_low = holderOf(labels, scanned.truth, low);
    MESSAGE("high top on patch " << on_high.patch << " (" << on_high.share << "), low top on patch " << on_low.patch
                                 << " (" << on_low.share << ")");
    CHECK(on_high.share > 0.8);
    CHECK(on_low.share > 0.8);
    CHECK(on_high.patch != on_low.patch);
  }
}

TEST_CASE("Seams: two desks side by side 1.5 cm apart in height, points 3 mm off them, are two patches") {
  for (const double cell : {0.05, 0.1}) {
    CAPTURE(cell);
    test::PlaneSceneBuilder scene(cell, 0.003, 1);
    const double o = cell / 3.0;  // the seam off the cells' boundaries
    scene.floor(o, o, 5.0 + o, 4.0 + o, 0.0)
        .floor(o, o, 5.0 + o, 4.0 + o, 2.6)
        .floor(1.0 + o, 1.0 + o, 2.4 + o, 1.75 + o, 0.75)
        .floor(2.4 + o, 1.0 + o, 3.8 + o, 1.75 + o, 0.735);
    const PlaneDetection detection = detectPlanes(scene.map());
    std::vector<const Plane*> desks = test::levelPatchesAt(detection, 0.74);
    REQUIRE(desks.size() >= 2);
    std::sort(desks.begin(), desks.end(),
              [](const Plane* a, const Plane* b) { return a->centroid.z() > b->centroid.z(); });
    // Each about its own 1.05 m² at its own height.
    CHECK(desks.front()->area < 1.4);
    CHECK(desks.back()->area < 1.4);
    CHECK(desks.front()->centroid.z() == doctest::Approx(0.75).epsilon(0.004));
    CHECK(desks.back()->centroid.z() == doctest::Approx(0.735).epsilon(0.004));
  }
}

TEST_CASE("Seams: a table top seen from two views a cm or two apart in height, overlapping, stays one patch") {
  // A 3 x 2 m top from two registered views 1.5 cm apart in height: the one covers it to
  // x 2.6, the other from x 2.2; their points 2 mm off. Where both reach, a block holds
  // both layers (it spreads by more than one surface's points): no seam runs there.
  for (const double cell : {0.05, 0.1}) {
    CAPTURE(cell);
    test::PlaneSceneBuilder scene(cell, 0.002, 1);
    const double o = cell / 3.0;
    scene.floor(1.0 + o, 1.0 + o, 2.6 + o, 3.0 + o, 0.75)
        .floor(2.2 + o, 1.0 + o, 4.0 + o, 3.0 + o, 0.765)
        .floor(o, o, 5.0 + o, 4.0 + o, 0.0)
        .floor(o, o, 5.0 + o, 4.0 + o, 2.6);
    const PlaneDetection detection = detectPlanes(scene.map());
    const std::vector<const Plane*> tops = test::levelPatchesAt(detection, 0.757);
    REQUIRE(!tops.empty());
    CHECK(tops.front()->area > 5.4);  // of 6 m²
  }
}

TEST_CASE("Seams: Bobkov's registered office cloud keeps its table top in one patch") {
  // Its views were registered a cm or two apart: the top is 2-3 cm thick, and from block to
  // block its height moves by more than the points' own spread (the 95th percentile of
  // neighbouring blocks' differences 1.4 cm at 5 cm cells, their points 0.3-0.5 cm): cut
  // at three such spreads instead of at that percentile, half of it went to a second patch.
  const auto data = test::sharedDataDir();
  if (!data) {
    MESSAGE("skipped: no shared data directory");
    return;
  }
  const Scan cloud = io::readPcd(*data / "bobkov_office_labels" / "room2_gt_fine.pcd");
  for (const double cell : {0.05, 0.1}) {
    CAPTURE(cell);
    // The top as bench/annotations/bobkov_room2.json marks it: its box, within 4 cm of z 2.171.
    const RegionOnPatches top = regionOnPatches(cloud, cell, [](const Point& p) {
      return p.x() >= 0.65 && p.x() <= 3.35 && p.y() >= 0.95 && p.y() <= 2.5 && std::abs(p.z() - 2.171) <= 0.04;
    });
    REQUIRE(top.points > 5000);
    MESSAGE(top.points << " points of the top, " << top.on_largest << " on its largest patch");
    CHECK(static_cast<double>(top.on_largest) > 0.9 * static_cast<double>(top.points));
  }
}

TEST_CASE("Seams: plane_seg's ANYmal stair map keeps its upper landing in one patch") {
  // An elevation map on a 2 cm grid: its landing's heights move from block to block by
  // more than the points in a block spread (the 95th percentile of neighbouring blocks'
  // differences 0.5 cm at 5 cm cells, their points 0.1 cm); cut at three such spreads
  // instead of at that percentile, at 10 cm cells 27 % of the landing went to a second patch.
  const auto data = test::sharedDataDir();
  if (!data) {
    MESSAGE("skipped: no shared data directory");
    return;
  }
  const Scan cloud = io::readPcd(*data / "plane_seg_stairs" / "ori_entrance_stair_climb_06.pcd");
  for (const double cell : {0.05, 0.1}) {
    CAPTURE(cell);
    // The landing as bench/annotations/stairs_anymal.json marks it (its box).
    const RegionOnPatches landing = regionOnPatches(cloud, cell, [](const Point& p) {
      return p.x() >= 3.42 && p.x() <= 5.3 && p.y() >= -0.4 && p.y() <= 2.2 && p.z() >= 1.15 && p.z() <= 1.38;
    });
    REQUIRE(landing.points > 5000);
    MESSAGE(landing.points << " points of the landing, " << landing.on_largest << " on its largest patch");
    CHECK(static_cast<double>(landing.on_largest) > 0.9 * static_cast<double>(landing.points));
  }
}
