// A cloud in a national grid's coordinates (x 500 km, y 5,000 km, heights of hundreds of
// metres) is mapped, its planes found and its points labelled as near the origin; where a
// layer's keys cannot reach it (the OcTree's, the registration's), the command says so.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "mlmap/error.hpp"
#include "mlmap/map/ml_map.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "mlmap/planes/point_labels.hpp"
#include "mlmap/registration/sequence_registration.hpp"
#include "mlmap/sim/placement.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"

using namespace mlmap;

namespace {

// 6 m x 4 m x 2.5 m, empty, two poses (as tests/test_planes_turned.cpp's).
constexpr const char* kBoxRoomJson = R"({
  "scan_pattern": {"angular_step_deg": 0.25, "tilt_start_deg": -60, "tilt_end_deg": 60,
                   "tilt_step_deg": 1.0, "range_sigma": 0.01, "mount_height": 1.2},
  "poses": [{"x": 2.2, "y": 1.7, "yaw_deg": 20}, {"x": 4.1, "y": 2.4, "yaw_deg": 200}],
  "surfaces": [
    {"type": "rectangle", "class": "floor", "min": [0, 0, 0], "max": [6, 4, 0]},
    {"type": "rectangle", "class": "ceiling", "min": [0, 0, 2.5], "max": [6, 4, 2.5]},
    {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [0, 4, 2.5]},
    {"type": "rectangle", "class": "wall", "min": [6, 0, 0], "max": [6, 4, 2.5]},
    {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [6, 0, 2.5]},
    {"type": "rectangle", "class": "wall", "min": [0, 4, 0], "max": [6, 4, 2.5]}
  ]
})";

const Eigen::Vector3d kNationalGrid(500000.0, 5000000.0, 300.0);

struct SurfaceFinding {
  sim::SurfaceClass kind;
  int patches = 0;             // patches on it: centroid within 10 cm, normal within 20 deg
  PlaneClass largest_class = PlaneClass::Other;
  double labelled_share = 0.0;  // of the points within 3 cm of it, the share on its largest patch
};

// The room turned 7 deg and moved by `shift` (plus a fraction of a 5 cm cell), simulated
// and mapped in 5 cm cells; its planes and every point's label; per true surface, the
// patches on it.
std::vector<SurfaceFinding> findSurfaces(const Eigen::Vector3d& shift) {
  sim::Scene scene = sim::parseScene(kBoxRoomJson, "box_room.json");
  sim::transformScene(scene, sim::Placement{0.013, 0.021, 7.0});
  std::vector<sim::SimulatedScan> scans = sim::simulate(scene);
  MLMap map(0.05);
  std::vector<Point> points;
  for (sim::SimulatedScan& simulated : scans) {
    simulated.scan.pose.pretranslate(shift);
    map.insertScan(simulated.scan);
    for (std::size_t k = 0; k < simulated.scan.size(); ++k) points.push_back(simulated.scan.worldPoint(k));
  }
  const PlaneDetection detection = detectPlanes(map);
  std::vector<std::int32_t> labels(points.size(), 0);
  {
    Scan all;
    all.points = points;
    labels = labelPoints(map, all);
  }
  refinePointLabels(map, detection.planes, points, labels, PointLabelRefinement{.noise = detection.config.noise});
  std::vector<SurfaceFinding> found;
  for (const sim::GroundTruthPlane& truth : scene.ground_truth) {
    const double d = truth.d - truth.normal.dot(shift);  // the true plane, moved
    SurfaceFinding surface{truth.surface_class};
    const Plane* largest = nullptr;
    for (const Plane& patch : detection.planes) {
      if (std::abs(truth.normal.dot(patch.centroid) + d) > 0.1 ||
          std::abs(patch.normal.dot(truth.normal)) < std::cos(20.0 * std::numbers::pi / 180.0))
        continue;
      ++surface.patches;
      if (largest == nullptr || patch.area > largest->area) largest = &patch;
    }
    if (largest != nullptr) {
      surface.largest_class = largest->label;
      std::size_t near = 0, on = 0;
      for (std::size_t k = 0; k < points.size(); ++k) {
        if (std::abs(truth.normal.dot(points[k]) + d) > 0.03) continue;
        ++near;
        on += labels[k] == largest->id ? 1 : 0;
      }
      surface.labelled_share = near > 0 ? static_cast<double>(on) / static_cast<double>(near) : 0.0;
    }
    found.push_back(surface);
  }
  return found;
}

}  // namespace

// Failed before: the blocks keep their points' positions in float, which 5,000 km out
// rounds by half a metre: of the four walls at most two were found, and the labels, whose
// planes' normals (unit to float precision) were scaled to unit length without their
// offsets, moved each plane by up to half a metre and left the walls' points unlabelled.
TEST_CASE("Far from the origin: a room in a national grid's coordinates gives each surface its patch and its points") {
  const std::vector<SurfaceFinding> near_origin = findSurfaces(Eigen::Vector3d::Zero());
  const std::vector<SurfaceFinding> far_out = findSurfaces(kNationalGrid);
  REQUIRE(near_origin.size() == 6);
  REQUIRE(far_out.size() == 6);
  for (std::size_t s = 0; s < far_out.size(); ++s) {
    CAPTURE(s);
    CAPTURE(far_out[s].patches);
    CAPTURE(far_out[s].labelled_share);
    CHECK(far_out[s].patches == near_origin[s].patches);
    CHECK(far_out[s].patches >= 1);
    CHECK(far_out[s].largest_class == near_origin[s].largest_class);
    CHECK(far_out[s].labelled_share > 0.9);
    CHECK(far_out[s].labelled_share == doctest::Approx(near_origin[s].labelled_share).epsilon(0.02));
  }
  // The classes themselves: the level raster of a floor is the map's grid, counted from the
  // grid's origin (their outlines were 500 km off, and no flight or floor was found).
  CHECK(far_out[0].largest_class == PlaneClass::Floor);
  CHECK(far_out[1].largest_class == PlaneClass::Ceiling);
  for (std::size_t s = 2; s < far_out.size(); ++s) CHECK(far_out[s].largest_class == PlaneClass::Wall);
}

// Failed before: block heights of 301.45 and 301.50 m, 5 cm apart when the build set them,
// are 4.9987 cm apart in float, under the part in 10^4 of a cell the reader allowed for
// rounding, and the map a build had written was refused as out of order.
TEST_CASE("Far from the origin: blocks 300 m up, a cell apart, are read back in order") {
  MLMap map(0.05);
  Block lower;
  lower.height = 301.454865F;
  lower.variance = 0.0009F;
  Block upper = lower;
  upper.height = 301.504852F;
  const Block blocks[] = {lower, upper};
  CHECK_NOTHROW(map.restoreCell(CellIndex{100000016, 9999949}, blocks));
  // Still refused: two blocks clearly less than a cell apart.
  MLMap other(0.05);
  upper.height = 301.49F;
  const Block close[] = {lower, upper};
  CHECK_THROWS_AS(other.restoreCell(CellIndex{0, 0}, close), Error);
}

// Failed before: the registration's voxel keys (OctoMap's, ±32,768 voxels) dropped every
// point, and `register` reported 0 inliers and kept the odometry, as if it had tried.
TEST_CASE("Far from the origin: registration says the scans lie beyond its keys' reach") {
  registration::SequenceRegistration sequence;
  Pose far = Pose::Identity();
  far.translation() = kNationalGrid;
  const std::vector<Point> points = {Point(1.0, 0.0, 0.0), Point(0.0, 2.0, 0.0), Point(0.0, 0.0, 1.0)};
  try {
    sequence.addScan(points, far);
    FAIL("no error");
  } catch (const Error& error) {
    CHECK(std::string(error.what()).find("nearer the origin") != std::string::npos);
  }
}

// Failed before: the OcTree's rays were dropped without a word, and the map held an empty
// OcTree. Now the build stops, says why and names --no-octree, which maps the blocks.
TEST_CASE("Far from the origin: build says the OcTree cannot reach the cloud, and maps it with --no-octree") {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "mlmap_far_origin_test";
  std::filesystem::create_directories(dir);
  const std::string scan = (dir / "far.xyz").string();
  {
    std::ofstream out(scan);
    for (int k = 0; k < 200; ++k) out << std::fixed << 500000.0 + 0.01 * k << " " << 5000000.0 << " " << 300.0 << "\n";
  }
  const std::string map = (dir / "far.mlmap").string();
  std::filesystem::remove(map);
  const auto refused = test::runCli("--quiet build --identity --min-range 0 --max-range 1e7 -o " + map + " " + scan);
  CHECK(refused.exit_code == 1);
  CHECK(refused.output.find("beyond the 3277 m the OcTree's keys reach") != std::string::npos);
  CHECK(refused.output.find("--no-octree") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(map));
  const auto built =
      test::runCli("--quiet build --identity --no-octree --min-range 0 --max-range 1e7 -o " + map + " " + scan);
  CHECK_MESSAGE(built.exit_code == 0, built.output);
  const auto info = test::runCli("info " + map);
  CHECK_MESSAGE(info.exit_code == 0, info.output);
  std::filesystem::remove_all(dir);
}
