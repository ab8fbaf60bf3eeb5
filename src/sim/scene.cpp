// Scene JSON loader, one file's own elements: every element is read through a JsonNode
// that knows its path, so each error names the file and the element ("lab.json:
// surfaces[3].size: ..."). Includes and openings: scene_include.cpp.
#include "mlmap/sim/scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "mlmap/error.hpp"
#include "scene_loader.hpp"

namespace mlmap::sim {
namespace {

using nlohmann::json;
using detail::JsonNode;

constexpr double kDegToRad = std::numbers::pi / 180.0;

// A surface before plane ids are assigned.
struct PendingSurface {
  Surface surface;
  std::optional<std::int32_t> plane_id;
  SurfaceClass surface_class = SurfaceClass::Other;
  std::string name;
  std::string path;  // JSON element, for messages
  int auto_group = -1;  // surfaces with the same group >= 0 share one auto-assigned id
};

struct SceneBuilder {
  std::vector<PendingSurface> surfaces;
  int next_group = 0;
};

SurfaceClass parseClass(const JsonNode& node) {
  const auto result = surfaceClassFromName(node.string());
  if (!result) node.fail("unknown class (floor, ceiling, wall, table, step or other)");
  return *result;
}

SurfaceClass classOr(const JsonNode& node, const std::string& key, SurfaceClass fallback) {
  return node.has(key) ? parseClass(node[key]) : fallback;
}

std::optional<std::int32_t> parsePlaneId(const JsonNode& node) {
  const std::int64_t id = node.integer();
  if (id < 0 || id > std::numeric_limits<std::int32_t>::max()) node.fail("must be a plane id >= 0");
  return static_cast<std::int32_t>(id);
}

Eigen::Vector3d parseFacing(const JsonNode& node) {
  static const std::map<std::string, Eigen::Vector3d, std::less<>> kFacings = {
      {"+x", Eigen::Vector3d::UnitX()},  {"-x", -Eigen::Vector3d::UnitX()},
      {"+y", Eigen::Vector3d::UnitY()},  {"-y", -Eigen::Vector3d::UnitY()},
      {"+z", Eigen::Vector3d::UnitZ()},  {"-z", -Eigen::Vector3d::UnitZ()}};
  const auto found = kFacings.find(node.string());
  if (found == kFacings.end()) node.fail("expected one of +x, -x, +y, -y, +z, -z");
  return found->second;
}

void parseRectangle(const JsonNode& node, SceneBuilder& builder) {
  node.allowOnly({"type", "name", "class", "plane", "min", "max", "facing", "corner", "center",
                  "edge_u", "edge_v"});
  PendingSurface pending;
  pending.path = node.path();
  pending.name = node.stringOr("name", "rectangle");
  pending.surface_class = classOr(node, "class", SurfaceClass::Other);
  if (node.has("plane")) pending.plane_id = parsePlaneId(node["plane"]);
  Surface& surface = pending.surface;

  if (node.has("min") || node.has("max")) {
    const Eigen::Vector3d lo = node["min"].vector3();
    const Eigen::Vector3d hi = node["max"].vector3();
    int flat_axis = -1;
    int flat_count = 0;
    for (int axis = 0; axis < 3; ++axis) {
      if (hi[axis] < lo[axis]) node["max"].fail("must not be below min");
      if (hi[axis] == lo[axis]) {
        flat_axis = axis;
        ++flat_count;
      }
    }
    if (flat_count != 1) node.fail("min and max must differ in exactly two coordinates");
    const int axis_u = (flat_axis + 1) % 3;
    const int axis_v = (flat_axis + 2) % 3;
    surface.corner = lo;
    surface.edge_u = Eigen::Vector3d::Zero();
    surface.edge_v = Eigen::Vector3d::Zero();
    surface.edge_u[axis_u] = hi[axis_u] - lo[axis_u];
    surface.edge_v[axis_v] = hi[axis_v] - lo[axis_v];
    if (node.has("facing")) {
      surface.normal = parseFacing(node["facing"]);
      if (surface.normal[flat_axis] == 0.0) node["facing"].fail("must be across the rectangle");
    } else {
      surface.normal = Eigen::Vector3d::Zero();
      surface.normal[flat_axis] =
          (flat_axis == 2 && pending.surface_class == SurfaceClass::Ceiling) ? -1.0 : 1.0;
    }
  } else {
    if (node.has("facing")) node["facing"].fail("only with min/max (edge_u × edge_v gives the side)");
    surface.edge_u = node["edge_u"].vector3();
    surface.edge_v = node["edge_v"].vector3();
    const Eigen::Vector3d cross = surface.edge_u.cross(surface.edge_v);
    if (cross.norm() < 1e-9) node.fail("edge_u and edge_v must span a rectangle (non-zero, not parallel)");
    surface.normal = cross.normalized();
    if (node.has("corner") == node.has("center")) node.fail("give exactly one of corner and center");
    surface.corner = node.has("corner")
                         ? node["corner"].vector3()
                         : Eigen::Vector3d(node["center"].vector3() - 0.5 * (surface.edge_u + surface.edge_v));
  }
  builder.surfaces.push_back(std::move(pending));
}

// An oriented box: the corner with the smallest local coordinates, the local x and y
// axes (unit, horizontal) and the sizes along local x, y, z.
struct OrientedBox {
  Eigen::Vector3d corner;
  Eigen::Vector3d axis_x;
  Eigen::Vector3d axis_y;
  Eigen::Vector3d size;
};

constexpr std::array<std::string_view, 6> kBoxFaces = {"bottom", "top", "x-", "x+", "y-", "y+"};

Surface boxFace(const OrientedBox& box, std::size_t face) {
  const Eigen::Vector3d ex = box.axis_x * box.size.x();
  const Eigen::Vector3d ey = box.axis_y * box.size.y();
  const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ() * box.size.z();
  Surface s;
  switch (face) {
    case 0: s = {box.corner, ex, ey, -Eigen::Vector3d::UnitZ(), 0}; break;
    case 1: s = {box.corner + ez, ex, ey, Eigen::Vector3d::UnitZ(), 0}; break;
    case 2: s = {box.corner, ey, ez, -box.axis_x, 0}; break;
    case 3: s = {box.corner + ex, ey, ez, box.axis_x, 0}; break;
    case 4: s = {box.corner, ex, ez, -box.axis_y, 0}; break;
    default: s = {box.corner + ey, ex, ez, box.axis_y, 0}; break;
  }
  return s;
}

std::size_t faceIndex(const JsonNode& node, const std::string& face) {
  const auto found = std::find(kBoxFaces.begin(), kBoxFaces.end(), face);
  if (found == kBoxFaces.end()) node.fail("unknown face \"" + face + "\" (bottom, top, x-, x+, y-, y+)");
  return static_cast<std::size_t>(found - kBoxFaces.begin());
}

void parseBox(const JsonNode& node, SceneBuilder& builder) {
  node.allowOnly({"type", "name", "class", "classes", "planes", "omit", "min", "max", "center", "size",
                  "yaw_deg"});
  const std::string name = node.stringOr("name", "box");
  const SurfaceClass default_class = classOr(node, "class", SurfaceClass::Other);

  Eigen::Vector3d center;
  Eigen::Vector3d size;
  if (node.has("min") || node.has("max")) {
    if (node.has("center") || node.has("size")) node.fail("give either min/max or center/size");
    const Eigen::Vector3d lo = node["min"].vector3();
    const Eigen::Vector3d hi = node["max"].vector3();
    if ((hi - lo).minCoeff() <= 0.0) node["max"].fail("must be above min in x, y and z");
    center = 0.5 * (lo + hi);
    size = hi - lo;
  } else {
    center = node["center"].vector3();
    size = node["size"].vector3();
    for (int axis = 0; axis < 3; ++axis) {
      if (!(size[axis] > 0.0)) node["size"][static_cast<std::size_t>(axis)].fail("must be positive");
    }
  }
  const double yaw = node.numberOr("yaw_deg", 0.0) * kDegToRad;
  OrientedBox box;
  box.axis_x = {std::cos(yaw), std::sin(yaw), 0.0};
  box.axis_y = {-std::sin(yaw), std::cos(yaw), 0.0};
  box.size = size;
  box.corner = center - 0.5 * (size.x() * box.axis_x + size.y() * box.axis_y) -
               0.5 * size.z() * Eigen::Vector3d::UnitZ();

  std::array<bool, 6> omitted{};
  if (node.has("omit")) {
    const JsonNode omit = node["omit"];
    for (std::size_t i = 0; i < omit.arraySize(); ++i) omitted[faceIndex(omit[i], omit[i].string())] = true;
  }
  std::array<std::optional<std::int32_t>, 6> plane_ids{};
  if (node.has("planes")) {
    const JsonNode planes = node["planes"];
    planes.expectObject();
    for (const auto& item : planes.value().items()) {
      plane_ids[faceIndex(planes, item.key())] = parsePlaneId(planes[item.key()]);
    }
  }
  std::array<SurfaceClass, 6> classes;
  classes.fill(default_class);
  if (node.has("classes")) {
    const JsonNode class_node = node["classes"];
    class_node.expectObject();
    for (const auto& item : class_node.value().items()) {
      classes[faceIndex(class_node, item.key())] = parseClass(class_node[item.key()]);
    }
  }
  for (std::size_t face = 0; face < kBoxFaces.size(); ++face) {
    if (omitted[face]) continue;
    PendingSurface pending;
    pending.surface = boxFace(box, face);
    pending.plane_id = plane_ids[face];
    pending.surface_class = classes[face];
    pending.name = name + "." + std::string(kBoxFaces[face]);
    pending.path = node.path();
    builder.surfaces.push_back(std::move(pending));
  }
}

// A straight solid staircase rising along its local +x: step i is a box from local x =
// i·tread to the back, so each step's tread and riser are visible and the steps' side
// faces form one staircase-shaped plane per side.
void parseStairs(const JsonNode& node, SceneBuilder& builder) {
  node.allowOnly({"type", "name", "class", "side_class", "start", "yaw_deg", "width", "steps",
                  "riser", "tread", "top_depth", "omit"});
  const std::string name = node.stringOr("name", "stairs");
  const SurfaceClass step_class = classOr(node, "class", SurfaceClass::Step);
  const SurfaceClass side_class = classOr(node, "side_class", SurfaceClass::Other);
  const JsonNode start_node = node["start"];
  if (!start_node.value().is_array() || (start_node.value().size() != 2 && start_node.value().size() != 3)) {
    start_node.fail("expected 2 or 3 numbers");
  }
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < start_node.value().size(); ++i) start[static_cast<Eigen::Index>(i)] = start_node[i].number();
  const double yaw = node.numberOr("yaw_deg", 0.0) * kDegToRad;
  const double width = node["width"].positive();
  const std::int64_t steps = node["steps"].integer();
  if (steps < 1 || steps > 1000) node["steps"].fail("must be between 1 and 1000");
  const double riser = node["riser"].positive();
  const double tread = node["tread"].positive();
  const double top_depth = node.positiveOr("top_depth", tread);
  const double depth = static_cast<double>(steps - 1) * tread + top_depth;

  bool omit_left = false;  // local y+ side
  bool omit_right = false;  // local y- side
  bool omit_back = false;
  if (node.has("omit")) {
    const JsonNode omit = node["omit"];
    for (std::size_t i = 0; i < omit.arraySize(); ++i) {
      const std::string face = omit[i].string();
      if (face == "left") omit_left = true;
      else if (face == "right") omit_right = true;
      else if (face == "back") omit_back = true;
      else omit[i].fail("unknown face (left, right or back)");
    }
  }
  const int left_group = builder.next_group++;
  const int right_group = builder.next_group++;
  const int back_group = builder.next_group++;

  OrientedBox box;
  box.axis_x = {std::cos(yaw), std::sin(yaw), 0.0};
  box.axis_y = {-std::sin(yaw), std::cos(yaw), 0.0};
  for (std::int64_t i = 0; i < steps; ++i) {
    const double offset = static_cast<double>(i) * tread;
    box.corner = start + offset * box.axis_x;
    box.size = {depth - offset, width, static_cast<double>(i + 1) * riser};
    auto add = [&](std::size_t face, SurfaceClass surface_class, const std::string& face_name, int group) {
      PendingSurface pending;
      pending.surface = boxFace(box, face);
      pending.surface_class = surface_class;
      pending.name = name + "." + face_name;
      pending.path = node.path();
      pending.auto_group = group;
      builder.surfaces.push_back(std::move(pending));
    };
    const std::string number = std::to_string(i + 1);
    add(1, step_class, "tread" + number, -1);
    add(2, step_class, "riser" + number, -1);
    if (!omit_right) add(4, side_class, "right", right_group);
    if (!omit_left) add(5, side_class, "left", left_group);
    if (!omit_back) add(3, side_class, "back", back_group);
  }
}

void parseCylinder(const JsonNode& node, Scene& scene) {
  node.allowOnly({"type", "name", "center", "radius", "z"});
  Cylinder cylinder;
  cylinder.center = node["center"].vector2();
  cylinder.radius = node["radius"].positive();
  const auto z = node["z"].numbers(2);
  if (!(z[1] > z[0])) node["z"].fail("expected [z_min, z_max] with z_max > z_min");
  cylinder.z_min = z[0];
  cylinder.z_max = z[1];
  scene.cylinders.push_back(cylinder);
}

ScanPattern parsePattern(const JsonNode& node) {
  node.allowOnly({"field_of_view_deg", "angular_step_deg", "tilt_start_deg", "tilt_end_deg",
                  "tilt_step_deg", "min_range", "max_range", "range_sigma", "mount_height", "seed"});
  ScanPattern pattern;
  pattern.field_of_view_deg = node.positiveOr("field_of_view_deg", pattern.field_of_view_deg);
  if (pattern.field_of_view_deg > 360.0) node["field_of_view_deg"].fail("must be at most 360");
  pattern.angular_step_deg = node.positiveOr("angular_step_deg", pattern.angular_step_deg);
  pattern.tilt_start_deg = node.numberOr("tilt_start_deg", pattern.tilt_start_deg);
  pattern.tilt_end_deg = node.numberOr("tilt_end_deg", pattern.tilt_end_deg);
  if (pattern.tilt_end_deg < pattern.tilt_start_deg) node["tilt_end_deg"].fail("must not be below tilt_start_deg");
  if (std::abs(pattern.tilt_start_deg) > 90.0 || std::abs(pattern.tilt_end_deg) > 90.0) {
    node.fail("tilt angles must lie within [-90, 90] degrees");
  }
  pattern.tilt_step_deg = node.positiveOr("tilt_step_deg", pattern.tilt_step_deg);
  pattern.min_range = node.nonNegativeOr("min_range", pattern.min_range);
  pattern.max_range = node.positiveOr("max_range", pattern.max_range);
  if (pattern.max_range <= pattern.min_range) node["max_range"].fail("must be above min_range");
  if (node.has("range_sigma")) pattern.range_sigma = node["range_sigma"].nonNegative();
  pattern.mount_height = node.positiveOr("mount_height", pattern.mount_height);
  if (node.has("seed")) pattern.seed = node["seed"].unsignedInteger();
  if (pattern.beamCount() * pattern.lineCount() > 100'000'000) node.fail("more than 1e8 beams per scan");
  return pattern;
}

OdometryDrift parseOdometry(const JsonNode& node) {
  node.allowOnly({"translation_noise_per_m", "yaw_noise_per_rad", "yaw_noise_per_m", "seed"});
  OdometryDrift drift;
  drift.translation_noise_per_m = node.nonNegativeOr("translation_noise_per_m", 0.0);
  drift.yaw_noise_per_rad = node.nonNegativeOr("yaw_noise_per_rad", 0.0);
  drift.yaw_noise_per_m = node.nonNegativeOr("yaw_noise_per_m", 0.0);
  if (node.has("seed")) drift.seed = node["seed"].unsignedInteger();
  return drift;
}

bool coplanar(const GroundTruthPlane& plane, const Surface& surface) {
  if (std::abs(plane.normal.dot(surface.normal)) < 1.0 - 1e-9) return false;
  for (const Eigen::Vector3d& point :
       {surface.corner, Eigen::Vector3d(surface.corner + surface.edge_u + surface.edge_v)}) {
    if (std::abs(plane.normal.dot(point) + plane.d) > 1e-6) return false;
  }
  return true;
}

// Explicit ids are kept; the others are numbered after the largest explicit id, in file
// order (one per surface, or one per auto group). Surfaces sharing an id must be coplanar
// and of one class.
void assignPlanes(SceneBuilder& builder, Scene& scene, const std::string& source) {
  std::int32_t next_id = 0;
  for (const auto& pending : builder.surfaces) {
    if (pending.plane_id) next_id = std::max(next_id, *pending.plane_id + 1);
  }
  std::map<int, std::int32_t> group_ids;
  std::map<std::int32_t, GroundTruthPlane> planes;
  for (auto& pending : builder.surfaces) {
    std::int32_t id;
    if (pending.plane_id) {
      id = *pending.plane_id;
    } else if (pending.auto_group >= 0) {
      const auto found = group_ids.find(pending.auto_group);
      id = found != group_ids.end() ? found->second : (group_ids[pending.auto_group] = next_id++);
    } else {
      id = next_id++;
    }
    pending.surface.plane_id = id;
    pending.surface.normal.normalize();
    const auto found = planes.find(id);
    if (found == planes.end()) {
      GroundTruthPlane plane;
      plane.id = id;
      plane.surface_class = pending.surface_class;
      // Adding 0.0 turns -0.0 into 0.0, so the exported JSON reads cleanly.
      plane.normal = (pending.surface.normal.array() + 0.0).matrix();
      plane.d = -plane.normal.dot(pending.surface.corner) + 0.0;
      plane.name = pending.name;
      planes.emplace(id, plane);
    } else {
      const GroundTruthPlane& plane = found->second;
      const std::string where = source + ": " + pending.path + ": plane " + std::to_string(id) + ": ";
      if (!coplanar(plane, pending.surface)) throw Error(where + "not coplanar with " + plane.name);
      if (plane.surface_class != pending.surface_class) {
        throw Error(where + "class " + std::string(className(pending.surface_class)) + " differs from " +
                    plane.name + "'s " + std::string(className(plane.surface_class)));
      }
      pending.surface.normal = plane.normal;
    }
    scene.surfaces.push_back(pending.surface);
  }
  for (auto& [id, plane] : planes) scene.ground_truth.push_back(std::move(plane));
}

}  // namespace

std::string_view className(SurfaceClass surface_class) {
  switch (surface_class) {
    case SurfaceClass::Floor: return "floor";
    case SurfaceClass::Ceiling: return "ceiling";
    case SurfaceClass::Wall: return "wall";
    case SurfaceClass::Table: return "table";
    case SurfaceClass::Step: return "step";
    case SurfaceClass::Other: break;
  }
  return "other";
}

std::optional<SurfaceClass> surfaceClassFromName(std::string_view name) {
  for (SurfaceClass candidate : {SurfaceClass::Floor, SurfaceClass::Ceiling, SurfaceClass::Wall,
                                 SurfaceClass::Table, SurfaceClass::Step, SurfaceClass::Other}) {
    if (className(candidate) == name) return candidate;
  }
  return std::nullopt;
}

std::size_t ScanPattern::beamCount() const {
  return static_cast<std::size_t>(std::floor(field_of_view_deg / angular_step_deg + 1e-9)) + 1;
}

std::size_t ScanPattern::lineCount() const {
  return static_cast<std::size_t>(std::floor((tilt_end_deg - tilt_start_deg) / tilt_step_deg + 1e-9)) + 1;
}

double ScanPattern::beamAngle(std::size_t beam) const {
  return (-0.5 * field_of_view_deg + static_cast<double>(beam) * angular_step_deg) * kDegToRad;
}

double ScanPattern::tiltAngle(std::size_t line) const {
  return (tilt_start_deg + static_cast<double>(line) * tilt_step_deg) * kDegToRad;
}

double ScanPattern::rangeSigma(double range) const {
  if (range_sigma) return *range_sigma;
  return range <= 10.0 ? 0.03 : 0.05;
}

Pose Scene::sensorPose(std::size_t index) const {
  const RobotPose& robot = poses.at(index);
  Pose pose = Pose::Identity();
  pose.translation() = Eigen::Vector3d(robot.x, robot.y, pattern.mount_height);
  pose.linear() = Eigen::AngleAxisd(robot.yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return pose;
}

std::optional<GroundTruthPlane> Scene::plane(std::int32_t id) const {
  const auto found = std::lower_bound(ground_truth.begin(), ground_truth.end(), id,
                                      [](const GroundTruthPlane& plane, std::int32_t key) { return plane.id < key; });
  if (found == ground_truth.end() || found->id != id) return std::nullopt;
  return *found;
}

namespace detail {

Scene parseSceneElements(const JsonNode& root, bool poses_required, bool surfaces_required) {
  Scene scene;
  scene.name = root.stringOr("name", "");
  if (root.has("scan_pattern")) scene.pattern = parsePattern(root["scan_pattern"]);
  if (root.has("odometry")) scene.odometry = parseOdometry(root["odometry"]);

  if (poses_required || root.has("poses")) {
    const JsonNode poses = root["poses"];
    if (poses.arraySize() == 0) poses.fail("expected at least one pose");
    for (std::size_t i = 0; i < poses.arraySize(); ++i) {
      const JsonNode pose = poses[i];
      pose.allowOnly({"x", "y", "yaw_deg"});
      scene.poses.push_back({pose["x"].number(), pose["y"].number(), pose.numberOr("yaw_deg", 0.0)});
    }
  }

  SceneBuilder builder;
  if (surfaces_required || root.has("surfaces")) {
    const JsonNode surfaces = root["surfaces"];
    for (std::size_t i = 0; i < surfaces.arraySize(); ++i) {
      const JsonNode surface = surfaces[i];
      surface.expectObject();
      const std::string type = surface["type"].string();
      if (type == "rectangle") parseRectangle(surface, builder);
      else if (type == "box") parseBox(surface, builder);
      else if (type == "stairs") parseStairs(surface, builder);
      else if (type == "cylinder") parseCylinder(surface, scene);
      else surface["type"].fail("unknown type \"" + type + "\" (rectangle, box, stairs, cylinder)");
    }
    if (builder.surfaces.empty() && surfaces_required) surfaces.fail("expected at least one planar surface");
  }
  assignPlanes(builder, scene, root.source());
  return scene;
}

nlohmann::json parseSceneDocument(std::string_view json_text, const std::string& source) {
  try {
    return json::parse(json_text.begin(), json_text.end());
  } catch (const json::exception& error) {
    // parse_error, or out_of_range for a number like 1e999; nlohmann's message reads
    // "[json.exception.parse_error.101] parse error at line 3, ..."
    std::string what = error.what();
    const auto bracket = what.find("] ");
    if (bracket != std::string::npos) what = what.substr(bracket + 2);
    throw Error(source + ": " + what);
  }
}

nlohmann::json readSceneDocument(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open scene file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw Error(path.string() + ": read error");
  return parseSceneDocument(text.str(), path.string());
}

}  // namespace detail

// Includes resolve against the directory of `source_name`.
Scene parseScene(std::string_view json_text, const std::string& source_name) {
  detail::IncludeChain chain;
  const auto document = detail::parseSceneDocument(json_text, source_name);
  return detail::assembleScene(document, source_name, std::filesystem::path(source_name).parent_path(), chain, true)
      .scene;
}

Scene loadScene(const std::filesystem::path& path) {
  std::error_code ignored;
  detail::IncludeChain chain = {std::filesystem::weakly_canonical(path, ignored)};
  return detail::assembleScene(detail::readSceneDocument(path), path.string(), path.parent_path(), chain, true)
      .scene;
}

}  // namespace mlmap::sim
