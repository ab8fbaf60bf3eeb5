// A cloud in a national grid's coordinates (x 500 km, y 5,000 km, heights of hundreds of
// metres) is mapped, registered, its planes found and its points labelled as near the
// origin: the map and the registration work in a frame near the cloud, and give the cloud's
// own coordinates back.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
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
#include "room_scenes.hpp"

using namespace mlmap;

namespace {

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
  sim::Scene scene = sim::parseScene(test::kBoxRoomJson, "box_room.json");
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
// point, and `register` reported 0 inliers and kept the odometry, as if it had tried. Now the
// sequence runs in a frame near its first scan and gives the same poses as near the origin.
TEST_CASE("Far from the origin: a sequence registers as near the origin, its poses in the scans' coordinates") {
  sim::Scene scene = sim::parseScene(test::kBoxRoomJson, "box_room.json");
  const std::vector<sim::SimulatedScan> scans = sim::simulate(scene);
  REQUIRE(scans.size() == 2);
  Pose start = scans[1].scan.pose;  // the second scan starts 5 cm and 1 deg off
  start.pretranslate(Eigen::Vector3d(0.05, -0.03, 0.0));
  start.rotate(Eigen::AngleAxisd(std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()));
  const auto run = [&](const Eigen::Vector3d& shift) {
    registration::SequenceRegistration sequence;
    Pose first = scans[0].scan.pose, second = start;
    first.pretranslate(shift);
    second.pretranslate(shift);
    sequence.addScan(scans[0].scan.points, first);
    const registration::VerifiedIcp result = sequence.addScan(scans[1].scan.points, second);
    CHECK(result.verified);
    CHECK((result.start.translation() - second.translation()).norm() < 1e-6);  // the world's, as given
    return sequence.poses();
  };
  const std::vector<Pose> near_origin = run(Eigen::Vector3d::Zero());
  const std::vector<Pose> far_out = run(kNationalGrid);
  REQUIRE(far_out.size() == 2);
  CHECK((far_out[1].translation() - kNationalGrid - scans[1].scan.pose.translation()).norm() < 0.01);
  CHECK((far_out[1].translation() - kNationalGrid - near_origin[1].translation()).norm() < 1e-4);
  const double turn = Eigen::AngleAxisd(far_out[1].linear().transpose() * near_origin[1].linear()).angle();
  CHECK(turn < 1e-4);  // rad
}

// Failed before: the OcTree's rays were dropped without a word and the map held an empty
// OcTree, the planes lost walls and classes, and the map could not be read back. Now the
// build puts the map's origin near the cloud, stores it, and `info`, `planes --json` and
// `label` speak the cloud's own coordinates; a scan beyond the OcTree's reach from that origin
// is refused with a message.
TEST_CASE("Far from the origin: build, planes and label of a cloud in a national grid's coordinates") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "mlmap_far_origin_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // A floor and a wall, 4 m by 3 m, 1 cm apart, at (500 km, 5,000 km), 300 m up.
  const std::string scan = (dir / "far.xyz").string();
  {
    std::ofstream out(scan);
    out << std::fixed;
    for (int a = 0; a < 400; ++a)
      for (int b = 0; b < 300; ++b) {
        out << 500000.0 + 0.01 * a << " " << 5000000.0 + 0.01 * b << " " << 300.0 << "\n";
        if (b < 250) out << 500000.0 + 0.01 * a << " " << 5000003.0 << " " << 300.0 + 0.01 * b << "\n";
      }
  }
  const std::string map = (dir / "far.mlmap").string(), planes = (dir / "far.planes.mlmap").string();
  const auto built = test::runCli("--quiet build --identity --min-range 0 --max-range 1e7 -o " + map + " " + scan);
  REQUIRE_MESSAGE(built.exit_code == 0, built.output);
  const auto info = test::runCli("info " + map);
  CHECK(info.output.find("origin         (500000.00, 5000000.00, 300.00) m") != std::string::npos);
  CHECK(info.output.find("x 500000.00..500004.00") != std::string::npos);
  CHECK(info.output.find("0 nodes") == std::string::npos);  // the OcTree holds the cloud
  const auto found = test::runCli("--quiet planes " + map + " -o " + planes + " --json " + (dir / "p.json").string());
  REQUIRE_MESSAGE(found.exit_code == 0, found.output);
  std::ifstream json_file(dir / "p.json");
  const std::string json((std::istreambuf_iterator<char>(json_file)), std::istreambuf_iterator<char>());
  CHECK(json.find("\"origin\":[500000.0,5000000.0,300.0]") != std::string::npos);
  CHECK(json.find("\"label\":\"floor\"") != std::string::npos);
  CHECK(json.find("\"label\":\"wall\"") != std::string::npos);
  const auto labelled = test::runCli("--quiet label " + planes + " --identity --min-range 0 --max-range 1e7 -o " +
                                     (dir / "l.xyz").string() + " " + scan);
  REQUIRE_MESSAGE(labelled.exit_code == 0, labelled.output);
  std::ifstream labels(dir / "l.xyz");
  double x = 0.0, y = 0.0, z = 0.0;
  int label = 0, on_plane = 0, total = 0;
  while (labels >> x >> y >> z >> label) {
    ++total;
    on_plane += label > 0 ? 1 : 0;
    if (total == 1) CHECK(x == doctest::Approx(500000.0).epsilon(1e-12));
  }
  CHECK(total == 400 * 300 + 400 * 250);
  CHECK(on_plane > 0.95 * total);
  // The same cloud 150 m further east has its own origin (500,200 m); merged in the scans'
  // frame (no transform), it lands 150 m east of the first, not at its origin.
  const std::string east = (dir / "east.xyz").string();
  {
    std::ifstream in(scan);
    std::ofstream out(east);
    out << std::fixed;
    while (in >> x >> y >> z) out << x + 150.0 << " " << y << " " << z << "\n";
  }
  const auto east_built = test::runCli("--quiet build --identity --min-range 0 --max-range 1e7 -o " +
                                       (dir / "east.mlmap").string() + " " + east);
  REQUIRE_MESSAGE(east_built.exit_code == 0, east_built.output);
  CHECK(test::runCli("info " + (dir / "east.mlmap").string()).output.find("origin         (500200.00") !=
        std::string::npos);
  const auto merged = test::runCli("--quiet merge " + map + " " + (dir / "east.mlmap").string() + " -o " +
                                   (dir / "both.mlmap").string());
  REQUIRE_MESSAGE(merged.exit_code == 0, merged.output);
  CHECK(test::runCli("info " + (dir / "both.mlmap").string()).output.find("x 500000.00..500154.00") !=
        std::string::npos);
  // A second scan 3 km from the first lies beyond the OcTree's reach from the origin the
  // first set (1,638 m at 5 cm voxels).
  const std::string farther = (dir / "farther.xyz").string();
  {
    std::ofstream out(farther);
    out << std::fixed << 503000.0 << " " << 5000000.0 << " " << 300.0 << "\n";
  }
  const auto refused = test::runCli("--quiet build --cell-size 0.05 --identity --min-range 0 --max-range 1e7 -o " +
                                    (dir / "two.mlmap").string() + " " + scan + " " + farther);
  CHECK(refused.exit_code == 1);
  CHECK(refused.output.find("beyond the 1638 m the OcTree's keys reach") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "two.mlmap"));
  fs::remove_all(dir);
}
