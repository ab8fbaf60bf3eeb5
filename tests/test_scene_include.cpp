// Scene includes (placement, plane ids, the output frame, cycles) and openings.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <string>

#include "helpers.hpp"
#include "mlmap/error.hpp"
#include "mlmap/sim/openings.hpp"
#include "mlmap/sim/ray_caster.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/placement.hpp"

namespace {

using mlmap::sim::GroundTruthPlane;
using mlmap::sim::loadScene;
using mlmap::sim::Placement;
using mlmap::sim::Scene;

// A 1 m wide, 2 m high wall along x at y = 0 facing +y, a floor and one pose.
const char* const kPartJson = R"({
  "name": "part",
  "poses": [{"x": 0.5, "y": 0.5, "yaw_deg": 10}],
  "surfaces": [
    {"type": "rectangle", "name": "wall", "class": "wall", "min": [0, 0, 0], "max": [1, 0, 2], "facing": "+y"},
    {"type": "rectangle", "name": "floor", "class": "floor", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"type": "cylinder", "name": "post", "center": [0.5, 0.8], "radius": 0.05, "z": [0, 1]}
  ]
})";

const std::string kOwnPoses = R"("poses": [{"x": 0, "y": 0}])";

std::optional<GroundTruthPlane> planeNamed(const Scene& scene, const std::string& name) {
  for (const auto& plane : scene.ground_truth) {
    if (plane.name == name) return plane;
  }
  return std::nullopt;
}

std::string loadError(const std::filesystem::path& path) {
  try {
    loadScene(path);
  } catch (const mlmap::Error& error) {
    return error.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("Scene include: the placement algebra") {
  const Placement placement{2.0, 1.0, 30.0};
  const Placement back = mlmap::sim::compose(placement, mlmap::sim::inverse(placement));
  CHECK(back.x == doctest::Approx(0.0));
  CHECK(back.y == doctest::Approx(0.0));
  CHECK(back.yaw_deg == doctest::Approx(0.0));
  const Placement other{-1.0, 3.0, -75.0};
  const mlmap::Pose composed = mlmap::sim::toPose(mlmap::sim::compose(placement, other));
  const mlmap::Pose expected = mlmap::sim::toPose(placement) * mlmap::sim::toPose(other);
  CHECK((composed.matrix() - expected.matrix()).cwiseAbs().maxCoeff() < 1e-12);
  // Quarter turns are exact.
  const mlmap::Pose quarter = mlmap::sim::toPose({0.0, 0.0, 90.0});
  CHECK(quarter.linear()(0, 0) == 0.0);
  CHECK(quarter.linear()(1, 0) == 1.0);
  CHECK(mlmap::sim::isIdentity({0.0, 0.0, 360.0}));
}

TEST_CASE("Scene include: a rectangle moved by x, y and yaw lands where expected") {
  mlmap::test::TempDir dir;
  mlmap::test::writeText(dir / "part.json", kPartJson);
  mlmap::test::writeText(dir / "top.json", "{" + kOwnPoses + R"(, "name": "top",
    "include": [{"scene": "part.json", "x": 2, "y": 1, "yaw_deg": 90}]})");
  const Scene scene = loadScene(dir / "top.json");
  CHECK(scene.name == "top");
  REQUIRE(scene.poses.size() == 1);
  CHECK(scene.poses[0].x == 0.0);  // the top file's own poses
  REQUIRE(scene.surfaces.size() == 2);
  // The wall's corner (0, 0, 0) goes to (2, 1, 0), its edge along x turns to +y.
  const auto& wall = scene.surfaces[0];
  CHECK(wall.corner == Eigen::Vector3d(2, 1, 0));
  const Eigen::Vector3d far = wall.corner + wall.edge_u + wall.edge_v;
  CHECK(far == Eigen::Vector3d(2, 2, 2));
  const auto plane = planeNamed(scene, "part/wall");
  REQUIRE(plane);
  CHECK(plane->normal == Eigen::Vector3d(-1, 0, 0));  // +y turned by 90°
  CHECK(plane->d == 2.0);                              // the plane x = 2
  REQUIRE(scene.cylinders.size() == 1);
  CHECK(scene.cylinders[0].center.x() == doctest::Approx(2.0 - 0.8));
  CHECK(scene.cylinders[0].center.y() == doctest::Approx(1.5));

  SUBCASE("any yaw: every corner is R·p + t") {
    mlmap::test::writeText(dir / "top30.json", "{" + kOwnPoses + R"(,
      "include": [{"scene": "part.json", "x": -1.5, "y": 4, "yaw_deg": 30}]})");
    const Scene turned = loadScene(dir / "top30.json");
    const mlmap::Pose motion = mlmap::sim::toPose({-1.5, 4.0, 30.0});
    const Eigen::Vector3d far_corner = turned.surfaces[0].corner + turned.surfaces[0].edge_u + turned.surfaces[0].edge_v;
    CHECK((turned.surfaces[0].corner - motion * Eigen::Vector3d(0, 0, 0)).norm() < 1e-9);
    CHECK((far_corner - motion * Eigen::Vector3d(1, 0, 2)).norm() < 1e-9);
    const auto turned_plane = planeNamed(turned, "part/wall");
    REQUIRE(turned_plane);
    const Eigen::Vector3d on_wall = motion * Eigen::Vector3d(0.3, 0, 1.1);
    CHECK(std::abs(turned_plane->normal.dot(on_wall) + turned_plane->d) < 1e-9);
  }
}

TEST_CASE("Scene include: plane ids stay unique, names get the include's scene name") {
  mlmap::test::TempDir dir;
  mlmap::test::writeText(dir / "part.json", kPartJson);
  mlmap::test::writeText(dir / "top.json", "{" + kOwnPoses + R"(,
    "include": [{"scene": "part.json"}, {"scene": "part.json", "x": 5}],
    "surfaces": [{"type": "rectangle", "name": "ceiling", "class": "ceiling", "min": [0, 0, 3], "max": [6, 1, 3]}]})");
  const Scene scene = loadScene(dir / "top.json");
  const Scene part = loadScene(dir / "part.json");
  REQUIRE(scene.ground_truth.size() == 2 * part.ground_truth.size() + 1);
  std::set<std::int32_t> ids;
  for (const auto& plane : scene.ground_truth) ids.insert(plane.id);
  CHECK(ids.size() == scene.ground_truth.size());
  for (const auto& surface : scene.surfaces) CHECK(scene.plane(surface.plane_id));
  // The first include keeps its ids; the file's own surfaces come last, unprefixed.
  CHECK(scene.plane(part.ground_truth.front().id)->name == "part/" + part.ground_truth.front().name);
  CHECK(scene.ground_truth.back().name == "ceiling");
  CHECK(scene.cylinders.size() == 2);
}

TEST_CASE("Scene include: the output frame is the frame of the scene with the poses") {
  mlmap::test::TempDir dir;
  mlmap::test::writeText(dir / "part.json", kPartJson);
  mlmap::test::writeText(dir / "other.json", R"({"name": "other", "surfaces": [
    {"type": "rectangle", "name": "wall", "class": "wall", "min": [0, 3, 0], "max": [4, 3, 2], "facing": "-y"}]})");
  mlmap::test::writeText(dir / "top.json", R"({"include": [
    {"scene": "other.json"},
    {"scene": "part.json", "x": 10, "y": 5, "yaw_deg": 90, "poses": true}]})");
  const Scene scene = loadScene(dir / "top.json");
  const Scene part = loadScene(dir / "part.json");
  // The provider's poses and surfaces read as in its own file.
  REQUIRE(scene.poses.size() == 1);
  CHECK(scene.poses[0].x == part.poses[0].x);
  CHECK(scene.poses[0].yaw_deg == part.poses[0].yaw_deg);
  CHECK(planeNamed(scene, "part/wall")->normal == part.ground_truth[0].normal);
  CHECK(planeNamed(scene, "part/wall")->d == part.ground_truth[0].d);
  // other.json's wall y = 3 (top frame) is x = 3 - 5 = -2 in part's frame.
  const auto wall = planeNamed(scene, "other/wall");
  REQUIRE(wall);
  const Eigen::Vector3d point_top(1.0, 3.0, 1.0);  // on other's wall, top frame
  const Eigen::Vector3d point_part = mlmap::sim::toPose({10.0, 5.0, 90.0}).inverse() * point_top;
  CHECK(point_part.x() == doctest::Approx(-2.0));
  CHECK(point_part.y() == doctest::Approx(9.0));
  CHECK(std::abs(wall->normal.dot(point_part) + wall->d) < 1e-12);
  CHECK(wall->normal == -Eigen::Vector3d::UnitX());  // -y turned by -90°
  CHECK(wall->d == -2.0);
  // A ray from the pose, in the output frame, along -x meets that wall 2.5 m away.
  const mlmap::sim::RayCaster caster(scene);
  const auto hit = caster.cast({0.5, 8.0, 1.0}, -Eigen::Vector3d::UnitX());
  REQUIRE(hit);
  CHECK(hit->range == doctest::Approx(2.5));
  CHECK(hit->plane_id == wall->id);

  SUBCASE("two scenes giving poses are refused") {
    mlmap::test::writeText(dir / "two.json", "{" + kOwnPoses + R"(,
      "include": [{"scene": "part.json", "poses": true}]})");
    CHECK(loadError(dir / "two.json").find("include[0].poses: this file has its own poses") != std::string::npos);
    mlmap::test::writeText(dir / "none.json", R"({"include": [{"scene": "part.json"}]})");
    CHECK(loadError(dir / "none.json").find("poses: missing") != std::string::npos);
  }
}

TEST_CASE("Scene include: nested placements compose into the provider's frame") {
  mlmap::test::TempDir dir;
  mlmap::test::writeText(dir / "part.json", kPartJson);
  mlmap::test::writeText(dir / "mid.json", R"({"include": [{"scene": "part.json", "y": 2, "yaw_deg": 90, "poses": true}]})");
  mlmap::test::writeText(dir / "top.json", R"({"include": [{"scene": "mid.json", "x": 1, "poses": true}],
    "surfaces": [{"type": "rectangle", "name": "far", "class": "wall", "min": [5, -3, 0], "max": [5, 3, 3]}]})");
  const Scene scene = loadScene(dir / "top.json");
  CHECK(scene.poses[0].x == 0.5);  // part's own
  // part's frame lies at (1, 2, 90°) in top's: top's wall x = 5 is part's y = -4.
  const auto far = planeNamed(scene, "far");
  REQUIRE(far);
  CHECK(far->normal == -Eigen::Vector3d::UnitY());
  CHECK(far->d == -4.0);
  CHECK(planeNamed(scene, "mid/part/wall"));
}

TEST_CASE("Scene include: cycles, depth and bad paths are refused with the file named") {
  mlmap::test::TempDir dir;
  mlmap::test::writeText(dir / "a.json", "{" + kOwnPoses + R"(, "include": [{"scene": "b.json"}]})");
  mlmap::test::writeText(dir / "b.json", R"({"include": [{"scene": "a.json"}]})");
  const std::string cycle = loadError(dir / "a.json");
  CHECK(cycle.find("include cycle a.json -> b.json -> a.json") != std::string::npos);

  mlmap::test::writeText(dir / "self.json", "{" + kOwnPoses + R"(, "include": [{"scene": "./self.json"}]})");
  CHECK(loadError(dir / "self.json").find("include cycle") != std::string::npos);

  mlmap::test::writeText(dir / "bad.json", "{" + kOwnPoses + R"(, "include": [{"scene": "nope.json"}]})");
  const std::string missing = loadError(dir / "bad.json");
  CHECK(missing.find("bad.json: include[0].scene: cannot open scene file") != std::string::npos);
  CHECK(missing.find("nope.json") != std::string::npos);

  // An error inside an included file names both files.
  mlmap::test::writeText(dir / "broken.json", R"({"surfaces": [{"type": "sphere"}]})");
  mlmap::test::writeText(dir / "uses_broken.json", "{" + kOwnPoses + R"(, "include": [{"scene": "broken.json"}]})");
  const std::string nested = loadError(dir / "uses_broken.json");
  CHECK(nested.find("uses_broken.json: include[0]: ") != std::string::npos);
  CHECK(nested.find("broken.json: surfaces[0].type: unknown type") != std::string::npos);

  // level0 includes level1 ... level5: five levels below the top are too deep.
  mlmap::test::writeText(dir / "part.json", kPartJson);
  mlmap::test::writeText(dir / "level5.json", R"({"include": [{"scene": "part.json", "poses": true}]})");
  for (int level = 4; level >= 0; --level) {
    mlmap::test::writeText(dir / ("level" + std::to_string(level) + ".json"),
                           R"({"include": [{"scene": "level)" + std::to_string(level + 1) + R"(.json", "poses": true}]})");
  }
  CHECK(loadError(dir / "level0.json").find("nested more than 4 deep") != std::string::npos);
  CHECK(loadError(dir / "level1.json").find("nested more than 4 deep") != std::string::npos);
  CHECK_NOTHROW(loadScene(dir / "level2.json"));  // level3, level4, level5, part
}

TEST_CASE("Scene openings: a door splits the wall, the hole is empty") {
  mlmap::test::TempDir dir;
  mlmap::test::writeText(dir / "room.json", "{" + kOwnPoses + R"(, "surfaces": [
      {"type": "rectangle", "name": "wall", "class": "wall", "min": [0, 0, 0], "max": [4, 0, 3]},
      {"type": "rectangle", "name": "floor", "class": "floor", "min": [0, -2, 0], "max": [4, 2, 0]}],
    "openings": [{"name": "door", "min": [1, -0.1, 0], "max": [2, 0.1, 2.1]}]})");
  const Scene scene = loadScene(dir / "room.json");
  REQUIRE(scene.ground_truth.size() == 2);
  // Above, left and right of the door (nothing below it); the floor only touches it.
  REQUIRE(scene.surfaces.size() == 3 + 1);
  double wall_area = 0.0;
  for (const auto& surface : scene.surfaces) {
    if (surface.plane_id == 0) wall_area += surface.edge_u.cross(surface.edge_v).norm();
    CHECK(surface.normal == scene.plane(surface.plane_id)->normal);
  }
  CHECK(wall_area == doctest::Approx(4.0 * 3.0 - 1.0 * 2.1));

  const mlmap::sim::RayCaster caster(scene);
  const Eigen::Vector3d across = -Eigen::Vector3d::UnitY();
  CHECK_FALSE(caster.cast({1.5, 1.0, 1.0}, across));  // through the door
  const auto beside = caster.cast({2.5, 1.0, 1.0}, across);
  REQUIRE(beside);
  CHECK(beside->range == doctest::Approx(1.0));
  CHECK(beside->plane_id == 0);
  const auto over = caster.cast({1.5, 1.0, 2.5}, across);  // the lintel's wall
  REQUIRE(over);
  CHECK(over->plane_id == 0);

  SUBCASE("a turned surface crossing an opening is an error") {
    mlmap::test::writeText(dir / "turned.json", "{" + kOwnPoses + R"(, "surfaces": [
        {"type": "rectangle", "name": "slanted", "corner": [0, 0, 0], "edge_u": [4, 1, 0], "edge_v": [0, 0, 3]}],
      "openings": [{"name": "door", "min": [1, -0.1, 0], "max": [2, 0.6, 2.1]}]})");
    const std::string error = loadError(dir / "turned.json");
    CHECK(error.find("turned.json: openings[0]: opening \"door\" crosses slanted") != std::string::npos);
  }
  SUBCASE("crossing against a brute-force sample of the surface") {
    const mlmap::sim::Opening box{{1.0, -0.1, 0.0}, {2.0, 0.1, 2.1}, "box"};
    std::mt19937 random(5);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    auto sampleNear = [&](const mlmap::sim::Surface& surface, double margin) {
      for (int i = 0; i <= 60; ++i) {
        for (int j = 0; j <= 60; ++j) {
          const Eigen::Vector3d p = surface.corner + (i / 60.0) * surface.edge_u + (j / 60.0) * surface.edge_v;
          if ((p.array() > box.min.array() - margin).all() && (p.array() < box.max.array() + margin).all()) return true;
        }
      }
      return false;
    };
    int crossing = 0;
    for (int k = 0; k < 300; ++k) {
      mlmap::sim::Surface surface;
      surface.corner = Eigen::Vector3d(1.5, 0.0, 1.0) + 1.5 * Eigen::Vector3d(uniform(random), uniform(random), uniform(random));
      surface.edge_u = 1.5 * Eigen::Vector3d(uniform(random), uniform(random), uniform(random));
      surface.edge_v = 1.5 * Eigen::Vector3d(uniform(random), uniform(random), uniform(random));
      const bool crosses = mlmap::sim::crosses(surface, box);
      if (sampleNear(surface, -1e-3)) CHECK_MESSAGE(crosses, "k = " << k);  // a sample inside
      if (crosses) CHECK_MESSAGE(sampleNear(surface, 0.06), "k = " << k);   // a sample next to it
      crossing += crosses ? 1 : 0;
    }
    CHECK(crossing > 20);
  }
}

TEST_CASE("Scene include: the shipped building scenes join the lab and the corridor") {
  const auto maps = mlmap::test::sourceDir() / "maps";
  const Scene lab = loadScene(maps / "lab.json");
  const Scene corridor = loadScene(maps / "corridor.json");
  const Scene from_lab = loadScene(maps / "building_lab.json");
  const Scene from_corridor = loadScene(maps / "building_corridor.json");

  // Same planes and ids in both, corridor first with its own ids; only the frame differs.
  REQUIRE(from_lab.ground_truth.size() == corridor.ground_truth.size() + lab.ground_truth.size() + 4);
  for (std::size_t i = 0; i < from_lab.ground_truth.size(); ++i) {
    CHECK(from_lab.ground_truth[i].id == from_corridor.ground_truth[i].id);
    CHECK(from_lab.ground_truth[i].name == from_corridor.ground_truth[i].name);
  }
  CHECK(from_corridor.ground_truth[5].name == "corridor/" + corridor.ground_truth[5].name);
  CHECK(from_corridor.ground_truth[5].id == corridor.ground_truth[5].id);
  CHECK(from_lab.poses.size() == lab.poses.size());
  CHECK(from_corridor.poses.size() == corridor.poses.size());
  CHECK(from_lab.pattern.tilt_step_deg == lab.pattern.tilt_step_deg);

  // In the lab's frame the lab's planes read as in lab.json, the corridor's north wall
  // is y = -0.2.
  for (const auto& plane : lab.ground_truth) {
    const auto placed = planeNamed(from_lab, "lab/" + plane.name);
    REQUIRE(placed);
    CHECK(placed->normal == plane.normal);
    CHECK(placed->d == doctest::Approx(plane.d).epsilon(1e-12));
  }
  const auto north = planeNamed(from_lab, "corridor/wall_north_east");
  REQUIRE(north);
  CHECK(north->normal == -Eigen::Vector3d::UnitY());
  CHECK(north->d == doctest::Approx(-0.2));

  // Through the door (lab x 3–4) a ray from the lab reaches the corridor's south wall;
  // beside it, it stops at the lab's south wall.
  const mlmap::sim::RayCaster caster(from_lab);
  const auto through = caster.cast({3.5, 1.0, 1.5}, -Eigen::Vector3d::UnitY());  // over the cabinet
  REQUIRE(through);
  CHECK(through->range == doctest::Approx(5.95));
  CHECK(from_lab.plane(through->plane_id)->name == "corridor/wall_south_west");
  const auto beside = caster.cast({2.5, 1.0, 1.0}, -Eigen::Vector3d::UnitY());
  REQUIRE(beside);
  CHECK(beside->range == doctest::Approx(1.0));
  CHECK(from_lab.plane(beside->plane_id)->name == "lab/wall_south");

  const mlmap::sim::RayCaster corridor_caster(from_corridor);
  const auto into_lab = corridor_caster.cast({25.5, 2.0, 1.0}, Eigen::Vector3d::UnitY());
  REQUIRE(into_lab);
  CHECK(into_lab->range == doctest::Approx(4.95 + 10.9 - 2.0));
  CHECK(from_corridor.plane(into_lab->plane_id)->name == "lab/cabinets_north.y-");
  const auto to_jamb = corridor_caster.cast({25.5, 4.85, 1.0}, Eigen::Vector3d::UnitX());
  REQUIRE(to_jamb);
  CHECK(to_jamb->range == doctest::Approx(0.5));
  CHECK(from_corridor.plane(to_jamb->plane_id)->name == "door_jamb_east");
}
