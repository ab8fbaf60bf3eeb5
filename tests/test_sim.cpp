// Scene loading, ray casting and the tilting-laser simulator.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "helpers.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/tum_poses.hpp"
#include "mlmap/sim/ray_caster.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"

namespace {

using mlmap::sim::parseScene;
using mlmap::sim::Scene;
using mlmap::sim::SurfaceClass;

// A closed 6 × 4 × 3 m room (floor in two pieces sharing one plane), a box, and a coarse
// noise-free scan pattern.
const char* const kRoomJson = R"({
  "name": "room",
  "scan_pattern": {"angular_step_deg": 1.0, "tilt_start_deg": -60, "tilt_end_deg": 60,
                   "tilt_step_deg": 2.0, "range_sigma": 0.0, "mount_height": 0.5},
  "odometry": {"translation_noise_per_m": 0.05, "yaw_noise_per_rad": 0.05, "seed": 3},
  "poses": [{"x": 1.0, "y": 1.0}, {"x": 2.5, "y": 2.0, "yaw_deg": 30}, {"x": 4.0, "y": 1.5, "yaw_deg": 170}],
  "surfaces": [
    {"type": "rectangle", "name": "floor", "class": "floor", "plane": 0, "min": [0, 0, 0], "max": [3, 4, 0]},
    {"type": "rectangle", "name": "floor", "class": "floor", "plane": 0, "min": [3, 0, 0], "max": [6, 4, 0]},
    {"type": "rectangle", "name": "ceiling", "class": "ceiling", "min": [0, 0, 3], "max": [6, 4, 3]},
    {"type": "rectangle", "name": "west", "class": "wall", "min": [0, 0, 0], "max": [0, 4, 3]},
    {"type": "rectangle", "name": "east", "class": "wall", "min": [6, 0, 0], "max": [6, 4, 3], "facing": "-x"},
    {"type": "rectangle", "name": "south", "class": "wall", "corner": [0, 0, 0], "edge_u": [6, 0, 0], "edge_v": [0, 0, 3]},
    {"type": "rectangle", "name": "north", "class": "wall", "center": [3, 4, 1.5], "edge_u": [0, 0, 3], "edge_v": [6, 0, 0]},
    {"type": "box", "name": "crate", "class": "other", "classes": {"top": "table"}, "min": [4.5, 3, 0], "max": [5.5, 3.8, 0.8],
     "omit": ["bottom"], "planes": {"top": 42}}
  ]
})";

Scene roomScene() { return parseScene(kRoomJson, "room.json"); }

std::string errorOf(const std::string& text) {
  try {
    parseScene(text, "bad.json");
  } catch (const mlmap::Error& error) {
    return error.what();
  }
  return "no error";
}

double maxPoseDifference(const mlmap::Pose& a, const mlmap::Pose& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

}  // namespace

TEST_CASE("Sim scene: planes, ids and classes from JSON") {
  const Scene scene = roomScene();
  CHECK(scene.name == "room");
  CHECK(scene.poses.size() == 3);
  CHECK(scene.surfaces.size() == 7 + 5);
  REQUIRE(scene.plane(0));
  CHECK(scene.plane(0)->surface_class == SurfaceClass::Floor);
  CHECK(scene.plane(0)->normal.isApprox(Eigen::Vector3d::UnitZ()));
  // Auto ids follow the largest explicit one (42), in file order.
  REQUIRE(scene.plane(43));
  CHECK(scene.plane(43)->name == "ceiling");
  CHECK(scene.plane(43)->normal.isApprox(-Eigen::Vector3d::UnitZ()));
  CHECK(scene.plane(43)->d == doctest::Approx(3.0));
  REQUIRE(scene.plane(45));
  CHECK(scene.plane(45)->normal.isApprox(-Eigen::Vector3d::UnitX()));
  CHECK(scene.plane(45)->d == doctest::Approx(6.0));
  REQUIRE(scene.plane(42));
  CHECK(scene.plane(42)->surface_class == SurfaceClass::Table);
  CHECK(scene.plane(42)->d == doctest::Approx(-0.8));
  CHECK(scene.ground_truth.size() == 6 + 5);
  CHECK(mlmap::sim::className(SurfaceClass::Step) == "step");
  CHECK(mlmap::sim::surfaceClassFromName("ceiling") == SurfaceClass::Ceiling);
  CHECK_FALSE(mlmap::sim::surfaceClassFromName("roof"));
  CHECK(scene.pattern.beamCount() == 271);
  CHECK(scene.pattern.lineCount() == 61);
}

TEST_CASE("Sim ray caster agrees with analytic answers") {
  const Scene scene = roomScene();
  const mlmap::sim::RayCaster caster(scene);

  SUBCASE("straight down hits the floor at the mount height") {
    const auto hit = caster.cast({1.0, 1.0, 0.5}, -Eigen::Vector3d::UnitZ());
    REQUIRE(hit);
    CHECK(hit->range == doctest::Approx(0.5));
    CHECK(hit->plane_id == 0);
  }
  SUBCASE("a ray onto a box face gets that face's plane id and class") {
    const auto top = caster.cast({5.0, 3.4, 2.0}, -Eigen::Vector3d::UnitZ());
    REQUIRE(top);
    CHECK(top->range == doctest::Approx(1.2));
    CHECK(top->plane_id == 42);
    const auto side = caster.cast({3.0, 3.5, 0.4}, Eigen::Vector3d::UnitX());
    REQUIRE(side);
    CHECK(side->range == doctest::Approx(1.5));
    const auto plane = scene.plane(side->plane_id);
    REQUIRE(plane);
    CHECK(plane->name == "crate.x-");
    CHECK(plane->surface_class == SurfaceClass::Other);
    CHECK(plane->normal.isApprox(-Eigen::Vector3d::UnitX()));
  }
  SUBCASE("oblique rays against the brute-force plane answer") {
    const Eigen::Vector3d origin(2.0, 2.0, 1.0);
    for (int k = 0; k < 36; ++k) {
      const double angle = k * 10.0 * std::numbers::pi / 180.0;
      const Eigen::Vector3d direction = Eigen::Vector3d(std::cos(angle), std::sin(angle), -0.3).normalized();
      // Nearest of the floor and the four walls (the crate is out of reach of these rays
      // only where it is not the nearest; check by comparing with every room plane).
      double expected = std::numeric_limits<double>::infinity();
      for (const auto& plane : scene.ground_truth) {
        const double denominator = plane.normal.dot(direction);
        if (std::abs(denominator) < 1e-12) continue;
        const double range = -(plane.normal.dot(origin) + plane.d) / denominator;
        const Eigen::Vector3d point = origin + range * direction;
        const bool inside_room = point.x() > -1e-9 && point.x() < 6 + 1e-9 && point.y() > -1e-9 &&
                                 point.y() < 4 + 1e-9 && point.z() > -1e-9 && point.z() < 3 + 1e-9;
        if (range > 0 && inside_room && plane.name.rfind("crate", 0) != 0) expected = std::min(expected, range);
      }
      const auto hit = caster.cast(origin, direction);
      REQUIRE(hit);
      const Eigen::Vector3d point = origin + hit->range * direction;
      const bool on_crate = point.x() >= 4.5 - 1e-9 && point.x() <= 5.5 + 1e-9 && point.y() >= 3 - 1e-9 &&
                            point.y() <= 3.8 + 1e-9 && point.z() <= 0.8 + 1e-9;
      if (!on_crate) CHECK(hit->range == doctest::Approx(expected));
      CHECK(hit->range <= expected + 1e-9);
    }
  }
  SUBCASE("a ray hitting nothing, or only beyond max range, gives no hit") {
    CHECK_FALSE(caster.cast({-1.0, 2.0, 1.0}, -Eigen::Vector3d::UnitX()));
    CHECK_FALSE(caster.cast({1.0, 1.0, 0.5}, -Eigen::Vector3d::UnitZ(), 0.0, 0.4));
    CHECK_FALSE(caster.cast({1.0, 1.0, 0.5}, -Eigen::Vector3d::UnitZ(), 0.6));
  }
  SUBCASE("cylinders hit from outside and have no plane") {
    Scene with_pillar = scene;
    with_pillar.cylinders.push_back({Eigen::Vector2d(2.0, 2.0), 0.25, 0.0, 3.0});
    const mlmap::sim::RayCaster pillar_caster(with_pillar);
    const auto hit = pillar_caster.cast({1.0, 2.0, 1.0}, Eigen::Vector3d::UnitX());
    REQUIRE(hit);
    CHECK(hit->range == doctest::Approx(0.75));
    CHECK(hit->plane_id == -1);
    const auto above = pillar_caster.cast({1.0, 2.0, 1.0}, Eigen::Vector3d(1, 0, 3).normalized());
    REQUIRE(above);
    CHECK(above->plane_id == 43);  // passes over the pillar to the ceiling
  }
}

TEST_CASE("Sim scan of a closed room: every beam hits, points lie on their planes") {
  const Scene scene = roomScene();
  mlmap::sim::SimulateOptions options;
  options.range_noise = false;
  std::size_t progress_calls = 0;
  options.progress = [&](std::size_t done, std::size_t total) {
    ++progress_calls;
    CHECK(done == progress_calls);
    CHECK(total == 3);
  };
  const auto scans = mlmap::sim::simulate(scene, options);
  CHECK(progress_calls == 3);
  REQUIRE(scans.size() == 3);
  for (std::size_t k = 0; k < scans.size(); ++k) {
    const mlmap::Scan& scan = scans[k].scan;
    CHECK(scan.size() == scene.pattern.beamCount() * scene.pattern.lineCount());
    REQUIRE(scan.labels.size() == scan.size());
    REQUIRE(scan.variances.size() == scan.size());
    CHECK(maxPoseDifference(scan.pose, scene.sensorPose(k)) == 0.0);
    CHECK(scan.pose.translation().z() == doctest::Approx(0.5));
    double worst = 0.0;
    for (std::size_t i = 0; i < scan.size(); ++i) {
      const auto plane = scene.plane(scan.labels[i]);
      REQUIRE(plane);
      worst = std::max(worst, std::abs(plane->normal.dot(scan.worldPoint(i)) + plane->d));
    }
    CHECK(worst < 1e-6);
  }
}

TEST_CASE("Sim beam geometry: tilt sign and sensor frame") {
  // A single beam straight ahead: positive tilt points it at the floor in front.
  Scene scene = roomScene();
  scene.pattern.field_of_view_deg = 0.1;
  scene.pattern.angular_step_deg = 1.0;  // one beam, λ = -0.05°
  scene.pattern.tilt_start_deg = 45.0;
  scene.pattern.tilt_end_deg = 45.0;
  mlmap::sim::SimulateOptions options;
  options.range_noise = false;
  const mlmap::Scan scan = mlmap::sim::simulateScan(scene, scene.sensorPose(0), 0, options);
  REQUIRE(scan.size() == 1);
  CHECK(scan.points[0].x() == doctest::Approx(0.5).epsilon(1e-3));
  CHECK(scan.points[0].z() == doctest::Approx(-0.5));
  CHECK(scan.labels[0] == 0);
  CHECK(scan.worldPoint(0).z() == doctest::Approx(0.0));
}

TEST_CASE("Sim open scene: rays into the void give no point") {
  Scene scene = parseScene(R"({"poses": [{"x": 0, "y": 0}],
      "scan_pattern": {"angular_step_deg": 1, "tilt_start_deg": 0, "tilt_end_deg": 30, "tilt_step_deg": 10, "max_range": 5},
      "surfaces": [{"type": "rectangle", "class": "floor", "min": [-10, -10, 0], "max": [10, 10, 0]}]})",
                           "open.json");
  const auto scans = mlmap::sim::simulate(scene);
  const std::size_t beams = scene.pattern.beamCount() * scene.pattern.lineCount();
  CHECK(scans[0].scan.size() > 0);
  CHECK(scans[0].scan.size() < beams);
  // tilt 0 is horizontal: no floor hit; UTM-30LX variance model when no sigma is given.
  for (double variance : scans[0].scan.variances) CHECK(variance == doctest::Approx(0.03 * 0.03));
}

TEST_CASE("Sim determinism: same seed, same scans at 1 and 2 threads") {
  Scene scene = roomScene();
  scene.pattern.range_sigma = 0.01;
  mlmap::sim::SimulateOptions one;
  one.threads = 1;
  mlmap::sim::SimulateOptions two;
  two.threads = 2;
  const auto a = mlmap::sim::simulate(scene, one);
  const auto b = mlmap::sim::simulate(scene, two);
  const auto c = mlmap::sim::simulate(scene, two);
  REQUIRE(a.size() == b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    CHECK(a[k].scan.points == b[k].scan.points);
    CHECK(a[k].scan.labels == b[k].scan.labels);
    CHECK(a[k].scan.variances == b[k].scan.variances);
    CHECK(b[k].scan.points == c[k].scan.points);
    CHECK(maxPoseDifference(a[k].odometry_pose, c[k].odometry_pose) == 0.0);
  }
  // The noise is there, and another seed gives another scan.
  const auto exact = mlmap::sim::simulate(scene, [] {
    mlmap::sim::SimulateOptions options;
    options.range_noise = false;
    return options;
  }());
  CHECK(a[0].scan.points != exact[0].scan.points);
  scene.pattern.seed = 2;
  const auto other = mlmap::sim::simulate(scene, one);
  CHECK(a[0].scan.points != other[0].scan.points);
}

TEST_CASE("Sim odometry: exact without drift, drifting and growing with it") {
  Scene scene = roomScene();
  scene.poses.clear();
  for (int i = 0; i < 30; ++i) scene.poses.push_back({0.5 * i, 0.1 * i, 3.0 * i});

  scene.odometry = {};
  const auto exact = mlmap::sim::odometryPoses(scene);
  REQUIRE(exact.size() == scene.poses.size());
  for (std::size_t i = 0; i < exact.size(); ++i) CHECK(maxPoseDifference(exact[i], scene.sensorPose(i)) < 1e-9);

  scene.odometry.translation_noise_per_m = 0.02;
  scene.odometry.yaw_noise_per_rad = 0.05;
  scene.odometry.yaw_noise_per_m = 0.01;
  // Mean position error over many seeds grows along the path.
  double early = 0.0;
  double late = 0.0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    scene.odometry.seed = seed;
    const auto drifting = mlmap::sim::odometryPoses(scene);
    CHECK(maxPoseDifference(drifting[0], scene.sensorPose(0)) == 0.0);
    CHECK(maxPoseDifference(drifting[1], scene.sensorPose(1)) > 0.0);
    CHECK(drifting[5].translation().z() == doctest::Approx(scene.pattern.mount_height));
    early += (drifting[3].translation() - scene.sensorPose(3).translation()).norm();
    late += (drifting[29].translation() - scene.sensorPose(29).translation()).norm();
  }
  CHECK(late > 3.0 * early);

  mlmap::sim::SimulateOptions options;
  options.odometry_drift = false;
  scene.pattern.tilt_end_deg = scene.pattern.tilt_start_deg;
  const auto scans = mlmap::sim::simulate(scene, options);
  for (std::size_t i = 0; i < scans.size(); ++i) CHECK(maxPoseDifference(scans[i].odometry_pose, scans[i].true_pose) == 0.0);
}

TEST_CASE("Sim bad scene JSON names the file and the element") {
  const std::string poses = R"("poses": [{"x": 0, "y": 0}])";
  CHECK(errorOf("{" + poses + "}") == "bad.json: surfaces: missing");
  CHECK(errorOf(R"({"surfaces": []})") == "bad.json: poses: missing");
  CHECK(errorOf("{" + poses + R"(, "surfaces": [{"type": "box", "center": [0, 0, 0], "size": [1, 2]}]})") ==
        "bad.json: surfaces[0].size: expected 3 numbers");
  CHECK(errorOf("{" + poses + R"(, "surfaces": [{"type": "box", "center": [0, 0, 0], "size": [1, -2, 1]}]})") ==
        "bad.json: surfaces[0].size[1]: must be positive");
  CHECK(errorOf("{" + poses + R"(, "surfaces": [{"type": "box", "min": [0, 0, 0], "max": [1, -2, 1]}]})") ==
        "bad.json: surfaces[0].max: must be above min in x, y and z");
  CHECK(errorOf("{" + poses + R"(, "surfaces": [{"type": "cylinder", "center": [0, 0], "radius": "big", "z": [0, 1]}]})") ==
        "bad.json: surfaces[0].radius: expected a number");
  CHECK(errorOf("{" + poses + R"(, "surfaces": [{"type": "rectangle", "min": [0, 0, 0]}]})") ==
        "bad.json: surfaces[0].max: missing");
  CHECK(errorOf("{" + poses + R"(, "surfaces": [{"type": "rectangle", "min": [0, 0, 0], "max": [1, 1, 0], "class": "roof"}]})") ==
        "bad.json: surfaces[0].class: unknown class (floor, ceiling, wall, table, step or other)");
  CHECK(errorOf("{" + poses + R"(, "surfaces": [{"type": "sphere"}]})") ==
        "bad.json: surfaces[0].type: unknown type \"sphere\" (rectangle, box, stairs, cylinder)");
  CHECK(errorOf("{" + poses + R"(, "surfaces": [{"type": "rectangle", "min": [0, 0, 0], "max": [1, 1, 0], "colour": 1}]})") ==
        "bad.json: surfaces[0].colour: unknown field");
  CHECK(errorOf(R"({"poses": [{"x": 0, "y": "0"}], "surfaces": []})") == "bad.json: poses[0].y: expected a number");
  CHECK(errorOf(R"({"poses": [], "surfaces": []})") == "bad.json: poses: expected at least one pose");
  CHECK(errorOf("{" + poses + R"(, "scan_pattern": {"tilt_step_deg": -1}, "surfaces": []})") ==
        "bad.json: scan_pattern.tilt_step_deg: must be positive");
  // Surfaces sharing a plane id must lie on one plane.
  CHECK(errorOf("{" + poses + R"(, "surfaces": [
      {"type": "rectangle", "name": "a", "plane": 1, "min": [0, 0, 0], "max": [1, 1, 0]},
      {"type": "rectangle", "name": "b", "plane": 1, "min": [0, 0, 1], "max": [1, 1, 1]}]})") ==
        "bad.json: surfaces[1]: plane 1: not coplanar with a");
  const std::string parse_error = errorOf("{\"poses\": [");
  CHECK(parse_error.rfind("bad.json: parse error", 0) == 0);

  mlmap::test::TempDir dir;
  CHECK_THROWS_WITH_AS(mlmap::sim::loadScene(dir / "missing.json"),
                       doctest::Contains("missing.json: cannot open"), mlmap::Error);
}

TEST_CASE("Sim shipped scenes load with the paper's dimensions") {
  const auto maps = mlmap::test::sourceDir() / "maps";
  auto floorBounds = [](const Scene& scene) {
    Eigen::AlignedBox3d box;
    for (const auto& surface : scene.surfaces) {
      const auto plane = scene.plane(surface.plane_id);
      if (plane->surface_class != SurfaceClass::Floor) continue;
      box.extend(surface.corner);
      box.extend(Eigen::Vector3d(surface.corner + surface.edge_u + surface.edge_v));
    }
    return box;
  };

  const Scene lab = mlmap::sim::loadScene(maps / "lab.json");
  const auto lab_floor = floorBounds(lab);
  CHECK(lab_floor.sizes().x() == doctest::Approx(8.3));
  CHECK(lab_floor.sizes().y() == doctest::Approx(11.4));
  CHECK(lab.poses.size() == 8);
  const std::size_t lab_beams = lab.pattern.beamCount() * lab.pattern.lineCount() * lab.poses.size();
  CHECK(lab_beams > 1'800'000);
  CHECK(lab_beams < 2'300'000);

  const Scene corridor = mlmap::sim::loadScene(maps / "corridor.json");
  const auto corridor_floor = floorBounds(corridor);
  CHECK(corridor_floor.sizes().x() == doctest::Approx(40.4));
  CHECK(corridor.poses.size() == 24);
  int steps = 0;
  for (const auto& plane : corridor.ground_truth) steps += plane.surface_class == SurfaceClass::Step ? 1 : 0;
  CHECK(steps >= 16);  // 8 treads and 8 risers

  // Every pose is inside the floor outline, above no obstacle: straight down hits a floor.
  for (const Scene* scene : {&lab, &corridor}) {
    const mlmap::sim::RayCaster caster(*scene);
    for (std::size_t i = 0; i < scene->poses.size(); ++i) {
      const auto hit = caster.cast(scene->sensorPose(i).translation(), -Eigen::Vector3d::UnitZ());
      REQUIRE(hit);
      CHECK(scene->plane(hit->plane_id)->surface_class == SurfaceClass::Floor);
      CHECK(hit->range == doctest::Approx(scene->pattern.mount_height));
    }
  }
}

TEST_CASE("Sim writeSimulation writes the peer scripts' files") {
  Scene scene = roomScene();
  scene.pattern.tilt_step_deg = 20.0;
  const auto scans = mlmap::sim::simulate(scene);
  mlmap::test::TempDir dir;
  mlmap::sim::writeSimulation(dir.path() / "out", scene, scans);
  for (const char* name : {"scan_000.xyz", "scan_001.xyz", "scan_002.xyz", "poses_true.txt", "poses_odom.txt",
                           "planes_true.json", "all_world.xyz"}) {
    CHECK_MESSAGE(std::filesystem::exists(dir.path() / "out" / name), name);
  }
  CHECK_FALSE(std::filesystem::exists(dir.path() / "out" / "scan_003.xyz"));
  const auto true_poses = mlmap::io::readTumPoses(dir.path() / "out" / "poses_true.txt");
  REQUIRE(true_poses.size() == 3);
  CHECK(true_poses[2].stamp == 2.0);
  CHECK(maxPoseDifference(true_poses[2].pose, scans[2].true_pose) < 1e-6);
  const std::string planes = mlmap::test::readText(dir.path() / "out" / "planes_true.json");
  CHECK(planes.find("\"class\": \"ceiling\"") != std::string::npos);
  const std::string world = mlmap::test::readText(dir.path() / "out" / "all_world.xyz");
  std::size_t lines = 0;
  for (char c : world) lines += c == '\n' ? 1 : 0;
  CHECK(lines == scans[0].scan.size() + scans[1].scan.size() + scans[2].scan.size());
}
