// The surface elements of a scene file: rectangles, boxes, flights of stairs and
// cylinders, each checked element by element (errors name the file and the element).
#include "scene_surfaces.hpp"

#include <array>
#include <cmath>
#include <numbers>

#include "mlmap/error.hpp"

namespace mlmap::sim::detail {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

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

}  // namespace

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

namespace {

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

}  // namespace

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

}  // namespace mlmap::sim::detail
