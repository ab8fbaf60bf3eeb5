// registration/up_axis.hpp: which way is up, from the planes a scan sees and the axis
// its poses turn about; and the turn that makes it +z.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "box_room_rays.hpp"
#include "mlmap/registration/up_axis.hpp"

using namespace mlmap;
using registration::estimateUpAxis;
using registration::UpCue;

namespace {

// A z-up room, x -2..4, y -3..1, floor 1 m below the sensor and ceiling 1.5 m above,
// scanned from the origin by rays spread evenly over the sphere (a Fibonacci lattice):
// near surfaces get denser readings, as a scanner's do.
std::vector<Point> roomScan(int rays = 40000) {
  std::vector<Point> points;
  for (const auto& ray : test::boxRoomRays(rays, {-2.0, -3.0, -1.0}, {4.0, 1.0, 1.5})) {
    points.push_back(ray.range * ray.direction);
  }
  return points;
}

Scan turned(const std::vector<Point>& points, const Eigen::Matrix3d& rotation) {
  Scan scan;
  for (const Point& point : points) scan.points.push_back(rotation * point);
  return scan;
}

Eigen::Matrix3d about(const Eigen::Vector3d& axis, double degrees) {
  return Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, axis).toRotationMatrix();
}

}  // namespace

TEST_CASE("Up axis: a z-up room is z-up, the same room y-up or x-down is found so, and turned back") {
  const std::vector<Point> room = roomScan();
  const auto z_up = estimateUpAxis({turned(room, Eigen::Matrix3d::Identity())});
  CHECK(z_up.line_from == UpCue::Planes);
  CHECK(z_up.up.isApprox(Eigen::Vector3d::UnitZ()));
  CHECK(z_up.below_share > 0.5);
  // Turning the room's z onto +y (a camera's frame after its VIEWPOINT, PCL's office1).
  const Eigen::Matrix3d to_y = about(Eigen::Vector3d::UnitX(), -90.0);
  REQUIRE((to_y * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitY()));
  const auto y_up = estimateUpAxis({turned(room, to_y)});
  CHECK(y_up.up.isApprox(Eigen::Vector3d::UnitY()));
  CHECK(std::string(registration::axisName(y_up.up)) == "+y");
  const auto x_down = estimateUpAxis({turned(room, about(Eigen::Vector3d::UnitY(), -90.0))});
  CHECK(x_down.up.isApprox(-Eigen::Vector3d::UnitX()));
  CHECK(std::string(registration::axisName(x_down.up)) == "-x");
  for (const Eigen::Vector3d& up : {Eigen::Vector3d(Eigen::Vector3d::UnitX()), Eigen::Vector3d(-Eigen::Vector3d::UnitX()),
                                    Eigen::Vector3d(Eigen::Vector3d::UnitY()), Eigen::Vector3d(-Eigen::Vector3d::UnitY()),
                                    Eigen::Vector3d(Eigen::Vector3d::UnitZ()), Eigen::Vector3d(-Eigen::Vector3d::UnitZ())}) {
    const Eigen::Matrix3d turn = registration::rotationToZUp(up);
    CHECK((turn * up).isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
    CHECK(turn.determinant() == doctest::Approx(1.0));
  }
  // The y-up room turned back holds its floor level again: 1 m below the sensor.
  const Scan back = turned(turned(room, to_y).points, registration::rotationToZUp(y_up.up));
  std::size_t on_floor = 0;
  for (const Point& point : back.points) on_floor += std::abs(point.z() + 1.0) < 1e-9 ? 1 : 0;
  CHECK(on_floor > back.points.size() / 5);
}

TEST_CASE("Up axis: scans that turn about one axis give its line, whatever the planes say") {
  // A corridor-like scene where one wall family outweighs the floor: the poses decide.
  const std::vector<Point> room = roomScan(8000);
  const Eigen::Matrix3d to_y = about(Eigen::Vector3d::UnitX(), -90.0);
  std::vector<Scan> scans;
  for (const double yaw : {0.0, 40.0, 95.0}) {
    Scan scan = turned(room, Eigen::Matrix3d::Identity());
    scan.pose = Pose(to_y * about(Eigen::Vector3d::UnitZ(), yaw));  // sensor z-up, world y-up
    scans.push_back(scan);
  }
  const auto estimate = estimateUpAxis(scans);
  CHECK(estimate.line_from == UpCue::Poses);
  CHECK(estimate.up.isApprox(Eigen::Vector3d::UnitY()));
  // No planes, no turn: no evidence, and up stays +z.
  Scan sparse;
  sparse.points = {Point(1, 0, 0), Point(0, 1, 0)};
  const auto none = estimateUpAxis({sparse});
  CHECK(none.line_from == UpCue::None);
  CHECK(none.up.isApprox(Eigen::Vector3d::UnitZ()));
}

TEST_CASE("Up axis: the first scan of a sequence with the sequence's poses gives the axis they turn about") {
  // `mlmap register --up auto --poses P scan_*.xyz` reads the first file only: its one scan has
  // no turn, and a tilting laser's scan of a narrow room faces its long walls more than its
  // floor (the stress benchmark's fresh room-22 read as x-up and was warned about). The pose
  // file's turns decide, as they do for scans read together.
  const Eigen::Matrix3d to_y = about(Eigen::Vector3d::UnitX(), -90.0);
  Scan first = turned(roomScan(8000), Eigen::Matrix3d::Identity());
  first.pose = Pose(to_y);
  std::vector<Pose> poses;
  for (const double yaw : {0.0, 40.0, 95.0}) poses.push_back(Pose(to_y * about(Eigen::Vector3d::UnitZ(), yaw)));
  const auto alone = estimateUpAxis({first});
  CHECK(alone.line_from == UpCue::Planes);
  const auto with_poses = estimateUpAxis({first}, {}, poses);
  CHECK(with_poses.line_from == UpCue::Poses);
  CHECK(with_poses.up.isApprox(Eigen::Vector3d::UnitY()));
}

TEST_CASE("Up axis: a long corridor's walls outnumber its floor, the plane its sensors moved in does not") {
  // A tilting laser in a corridor 30 m long and 2.2 m wide: its two walls hold most of the
  // planar cells, and `mlmap register` on the stress benchmark's long corridor warned that
  // the data look y-up (and `--up auto` would have turned them). The poses of a robot lie in
  // one horizontal plane (along the corridor, a few decimetres across it, at one height):
  // its normal is up.
  std::vector<Point> points;
  for (const auto& ray : test::boxRoomRays(40000, {-15.0, -1.1, -1.2}, {15.0, 1.1, 1.6})) {
    points.push_back(ray.range * ray.direction);
  }
  Scan first = turned(points, Eigen::Matrix3d::Identity());
  std::vector<Pose> poses;
  for (int k = 0; k < 6; ++k) {
    Pose pose = Pose::Identity();
    pose.translation() = Eigen::Vector3d(1.7 * k, k % 2 == 0 ? 0.0 : 0.35, 0.0);
    poses.push_back(pose);
  }
  const auto alone = estimateUpAxis({first});
  CHECK(alone.line_from == UpCue::Planes);
  CHECK(std::abs(alone.up.y()) > 0.5);  // the walls' family: why the positions are needed
  const auto with_poses = estimateUpAxis({first}, {}, poses);
  CHECK(with_poses.line_from == UpCue::Positions);
  CHECK(with_poses.up.isApprox(Eigen::Vector3d::UnitZ()));

  // The same turned y-up: the positions lie in x-z, their normal is y.
  const Eigen::Matrix3d to_y = about(Eigen::Vector3d::UnitX(), -90.0);
  Scan first_y = turned(points, Eigen::Matrix3d::Identity());
  first_y.pose = Pose(to_y);
  std::vector<Pose> poses_y;
  for (const Pose& pose : poses) poses_y.push_back(Pose(to_y) * pose);
  const auto turned_y = estimateUpAxis({first_y}, {}, poses_y);
  CHECK(turned_y.line_from == UpCue::Positions);
  CHECK(turned_y.up.isApprox(Eigen::Vector3d::UnitY()));

  // A hand-held sensor bobbing up and down by a good part of its walk tells nothing.
  std::vector<Pose> bobbing = poses;
  for (std::size_t k = 0; k < bobbing.size(); ++k) bobbing[k].translation().z() = k % 3 == 0 ? 0.6 : -0.3;
  CHECK(estimateUpAxis({first}, {}, bobbing).line_from == UpCue::Planes);
}

TEST_CASE("Up axis: planes that face no coordinate axis give no line (a tilted camera is not x-up)") {
  // PCL's table_scene_mug_stereo_textured.pcd: a stereo camera looking down at a table,
  // whose plane lies 32 deg from every axis; `--up auto` read that as "+x (0 % of the
  // planar cells face it)" and turned the cloud on its side. The room turned 32 deg about
  // x and 30 deg about z: none of its surfaces faces a coordinate axis within 15 deg.
  const Eigen::Matrix3d tilt = about(Eigen::Vector3d::UnitZ(), 30.0) * about(Eigen::Vector3d::UnitX(), 32.0);
  const auto tilted = estimateUpAxis({turned(roomScan(), tilt)});
  CHECK(tilted.planar_cells >= 20);
  CHECK(tilted.line_from == UpCue::None);
  CHECK(tilted.up.isApprox(Eigen::Vector3d::UnitZ()));
  CHECK(tilted.planar_share == 0.0);
  CHECK(tilted.faces_no_axis);
  CHECK_FALSE(estimateUpAxis({turned(roomScan(), Eigen::Matrix3d::Identity())}).faces_no_axis);
}

namespace {

// A depth camera's view of the z-up room (test::cameraViewPoints), with the pose PCL's
// office1.pcd has (VIEWPOINT: a half turn about x), whose world is then the optical frame
// upside down: y-up where the camera is level.
Scan cameraView(const Eigen::Matrix3d& turn, bool from_image = true) {
  Scan scan;
  scan.from_image = from_image;
  scan.points = test::cameraViewPoints(turn, 60000, {-2.0, -3.0, -1.0}, {4.0, 1.0, 1.5});
  scan.pose = Pose(about(Eigen::Vector3d::UnitX(), 180.0));
  return scan;
}

}  // namespace

TEST_CASE("Up axis: a depth camera's single view is up where its image's down says, not where the wall it faces does") {
  // PCL's office1.pcd, a Kinect's organized cloud of an office: its VIEWPOINT makes the world
  // y-up, its far wall holds most planar cells, and `--up auto` read it as z-up (the wall's
  // axis) and nothing warned. Here the wall ahead outweighs the floor strip in view likewise.
  const Scan view = cameraView(Eigen::Matrix3d::Identity());
  REQUIRE(view.points.size() > 3000);
  const auto estimate = estimateUpAxis({view});
  CHECK(estimate.line_from == UpCue::Image);
  CHECK(estimate.up.isApprox(Eigen::Vector3d::UnitY()));
  CHECK_FALSE(estimate.faces_no_axis);
  CHECK(estimate.below_share > 0.5);  // the floor in view lies below the camera
  // The same points read as an unorganized cloud: the planes alone, and the far wall wins.
  const auto planes_only = estimateUpAxis({cameraView(Eigen::Matrix3d::Identity(), false)});
  CHECK(planes_only.line_from == UpCue::Planes);
  CHECK_FALSE(planes_only.up.isApprox(Eigen::Vector3d::UnitY()));

  // A spinning lidar's organized scan (rows of rings) lies all round its sensor: no image.
  Scan rings = turned(roomScan(), about(Eigen::Vector3d::UnitX(), -90.0));
  rings.from_image = true;
  const auto lidar = estimateUpAxis({rings});
  CHECK(lidar.line_from == UpCue::Planes);
  CHECK(lidar.up.isApprox(Eigen::Vector3d::UnitY()));

  // A camera looking down 32 deg at a table, turned 30 deg in the room (PCL's
  // table_scene_mug_stereo_textured.pcd): the image's down is the nearest axis to up, and
  // the surfaces say the view is tilted.
  const Scan down_at = cameraView(about(Eigen::Vector3d::UnitZ(), 30.0) * about(Eigen::Vector3d::UnitY(), 32.0));
  REQUIRE(down_at.points.size() > 3000);
  const auto tilted = estimateUpAxis({down_at});
  CHECK(tilted.line_from == UpCue::Image);
  CHECK(tilted.up.isApprox(Eigen::Vector3d::UnitY()));
  CHECK(tilted.faces_no_axis);
}

// A scanner standing off level (3DTK's three scans: 4.3 deg of pitch and 1 deg of roll by
// `mlmap calibrate`): the room's floor and ceiling lean off z, and its walls across the map's
// cell rows (build --level turns them back).
TEST_CASE("Up axis: the level surfaces of a room pitched 3 deg and rolled 1 deg are measured to 0.2 deg and levelled") {
  const std::vector<Point> room = roomScan();
  const auto level = registration::levelNormal({turned(room, Eigen::Matrix3d::Identity())}, Eigen::Vector3d::UnitZ());
  REQUIRE(level);
  CHECK(std::acos(level->z()) * 180.0 / std::numbers::pi < 0.2);
  const Eigen::Matrix3d tilt = about(Eigen::Vector3d::UnitY(), 3.0) * about(Eigen::Vector3d::UnitX(), 1.0);
  const Scan tilted_room = turned(room, tilt);
  // z-up still, by its planes; about -z the same normal, on -z's side.
  CHECK(estimateUpAxis({tilted_room}).up.isApprox(Eigen::Vector3d::UnitZ()));
  const auto tilted = registration::levelNormal({tilted_room}, Eigen::Vector3d::UnitZ());
  const auto below = registration::levelNormal({tilted_room}, -Eigen::Vector3d::UnitZ());
  REQUIRE(tilted);
  REQUIRE(below);
  const Eigen::Vector3d truth = tilt * Eigen::Vector3d::UnitZ();
  CHECK(std::acos(std::min(1.0, tilted->dot(truth))) * 180.0 / std::numbers::pi < 0.2);
  CHECK(below->isApprox(-*tilted, 1e-12));
  // Levelled, the floor (1 m below the sensor before the tilt) is level again: 6 m of it
  // within 0.2 deg.
  const Scan back = turned(tilted_room.points, registration::rotationToLevel(*tilted));
  std::vector<double> floor;
  for (std::size_t k = 0; k < room.size(); ++k)
    if (std::abs(room[k].z() + 1.0) < 1e-9) floor.push_back(back.points[k].z());
  REQUIRE(floor.size() > 1000);
  const auto [low, high] = std::minmax_element(floor.begin(), floor.end());
  CHECK(*high - *low < 6.0 * std::tan(0.2 * std::numbers::pi / 180.0));
  // A wall alone faces no z: nothing to level by.
  std::vector<Point> wall;
  for (const Point& point : room)
    if (std::abs(point.x() - 4.0) < 1e-9) wall.push_back(point);
  CHECK_FALSE(registration::levelNormal({turned(wall, Eigen::Matrix3d::Identity())}, Eigen::Vector3d::UnitZ()));
}
