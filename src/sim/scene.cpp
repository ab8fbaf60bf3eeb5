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
#include "mlmap/io/regular_file.hpp"
#include "scene_loader.hpp"
#include "scene_surfaces.hpp"

namespace mlmap::sim {
namespace {

using nlohmann::json;
using detail::JsonNode;
using detail::PendingSurface;
using detail::SceneBuilder;

constexpr double kDegToRad = std::numbers::pi / 180.0;

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
  // Read to its end: a device or a pipe never ends (/dev/zero filled the memory).
  io::refuseNonRegularFile(path);
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
