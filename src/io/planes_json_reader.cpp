// Reading the planes export (schema mlmap.planes/1) back into a PlaneDetection.
// The text may come from anywhere: every field is checked for presence, type and
// range, and an error names the element the way a JSON path would.
#include <cmath>
#include <limits>
#include <set>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "file_bytes.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/planes_json.hpp"

namespace mlmap::io {
namespace {

using nlohmann::json;

// An outline longer than this is not something the writer makes: refuse it rather
// than hold an attacker's array.
constexpr std::size_t kMaxOutlineCorners = 1 << 20;

class Reader {
 public:
  explicit Reader(std::string name) : name_(std::move(name)) {}

  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw Error(name_ + ": " + where + ": " + what);
  }

  const json& member(const json& object, const std::string& where, const char* key) const {
    if (!object.is_object()) fail(where, "expected an object");
    const auto found = object.find(key);
    if (found == object.end()) fail(where, std::string("missing \"") + key + "\"");
    return *found;
  }

  double number(const json& value, const std::string& where) const {
    if (!value.is_number()) fail(where, "expected a number");
    const double result = value.get<double>();
    if (!std::isfinite(result)) fail(where, "not a finite number");
    return result;
  }

  double number(const json& object, const std::string& where, const char* key) const {
    return number(member(object, where, key), where + "." + key);
  }

  std::int64_t integer(const json& object, const std::string& where, const char* key, std::int64_t min,
                       std::int64_t max) const {
    const json& value = member(object, where, key);
    const std::string path = where + "." + key;
    if (!value.is_number_integer()) fail(path, "expected an integer");
    if (value.is_number_unsigned() && value.get<std::uint64_t>() > static_cast<std::uint64_t>(max)) {
      fail(path, "out of range");
    }
    const auto result = value.get<std::int64_t>();
    if (result < min || result > max) fail(path, "out of range [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    return result;
  }

  Eigen::Vector3d vector3(const json& value, const std::string& where) const {
    if (!value.is_array() || value.size() != 3) fail(where, "expected 3 numbers");
    return {number(value[0], where + "[0]"), number(value[1], where + "[1]"), number(value[2], where + "[2]")};
  }

  Eigen::Vector3d vector3(const json& object, const std::string& where, const char* key) const {
    return vector3(member(object, where, key), where + "." + key);
  }

 private:
  std::string name_;
};

PlaneClass planeClass(const Reader& reader, const json& value, const std::string& where) {
  if (value.is_string()) {
    const std::string text = value.get<std::string>();
    for (PlaneClass candidate : {PlaneClass::Floor, PlaneClass::Ceiling, PlaneClass::Wall, PlaneClass::Table,
                                 PlaneClass::Step, PlaneClass::Other}) {
      if (className(candidate) == text) return candidate;
    }
  }
  reader.fail(where, "expected one of floor, ceiling, wall, table, step, other");
}

// The parameters the export lists; names it does not know are allowed (the schema
// lets later writers add numbers) and ignored.
ErmsmConfig readParameters(const Reader& reader, const json& parameters) {
  const std::string where = "parameters";
  constexpr std::int64_t kIntMax = std::numeric_limits<int>::max();
  ErmsmConfig config;
  config.radius = static_cast<int>(reader.integer(parameters, where, "radius_cells", 0, kIntMax));
  config.epsilon = reader.number(parameters, where, "epsilon");
  config.kappa_deg = reader.number(parameters, where, "kappa_deg");
  config.theta_deg = reader.number(parameters, where, "theta_deg");
  config.min_probability = reader.number(parameters, where, "min_probability");
  config.min_area = reader.number(parameters, where, "min_area");
  config.max_candidates = static_cast<int>(reader.integer(parameters, where, "max_candidates", 0, kIntMax));
  config.seed = static_cast<std::uint64_t>(
      reader.integer(parameters, where, "seed", 0, std::numeric_limits<std::int64_t>::max()));
  const auto optional_number = [&](const char* key, auto& field) {
    using Field = std::remove_reference_t<decltype(field)>;
    if (!parameters.contains(key)) return;
    const double value = reader.number(parameters, where, key);
    if constexpr (std::is_integral_v<Field>) {
      // A double outside the integer's range would make the conversion undefined.
      if (!(value >= static_cast<double>(std::numeric_limits<Field>::min()) &&
            value <= static_cast<double>(std::numeric_limits<Field>::max()))) {
        reader.fail(where + "." + key, "out of range");
      }
    }
    field = static_cast<Field>(value);
  };
  optional_number("acceptance_exponent", config.acceptance_exponent);
  optional_number("min_patch_width_cells", config.min_patch_width_cells);
  optional_number("min_level_patch_width_cells", config.min_level_patch_width_cells);
  optional_number("min_patch_area", config.min_patch_area);
  optional_number("max_idle_candidates", config.max_idle_candidates);
  optional_number("min_patch_blocks", config.min_patch_blocks);
  optional_number("max_direction_spread_deg", config.max_direction_spread_deg);
  optional_number("batch_size", config.batch_size);
  optional_number("max_refits", config.max_refits);
  optional_number("refit_gain", config.refit_gain);
  optional_number("noise", config.noise);
  optional_number("max_epsilon", config.max_epsilon);
  optional_number("stack_gap", config.stack_gap);
  optional_number("ladder_gap", config.ladder_gap);
  optional_number("ladder_blocks", config.ladder_blocks);
  optional_number("sparse_gap", config.sparse_gap);
  return config;
}

Plane readPlane(const Reader& reader, const json& entry, const std::string& where) {
  constexpr std::int64_t kIdMax = std::numeric_limits<std::int32_t>::max();
  Plane plane;
  plane.id = static_cast<std::int32_t>(reader.integer(entry, where, "id", 1, kIdMax));
  plane.label = planeClass(reader, reader.member(entry, where, "label"), where + ".label");
  plane.normal = reader.vector3(entry, where, "normal");
  if (std::abs(plane.normal.norm() - 1.0) > 1e-3) reader.fail(where + ".normal", "not a unit vector");
  plane.offset = reader.number(entry, where, "offset");
  plane.centroid = reader.vector3(entry, where, "centroid");
  plane.area = reader.number(entry, where, "area");
  if (plane.area < 0.0) reader.fail(where + ".area", "negative");
  plane.block_count = static_cast<std::size_t>(
      reader.integer(entry, where, "blocks", 1, std::numeric_limits<std::int64_t>::max()));
  plane.rms = reader.number(entry, where, "rms");
  if (plane.rms < 0.0) reader.fail(where + ".rms", "negative");
  const json& outline = reader.member(entry, where, "outline");
  if (!outline.is_array()) reader.fail(where + ".outline", "expected an array");
  if (outline.size() > kMaxOutlineCorners) reader.fail(where + ".outline", "too many corners");
  plane.outline.reserve(outline.size());
  for (std::size_t k = 0; k < outline.size(); ++k) {
    plane.outline.push_back(reader.vector3(outline[k], where + ".outline[" + std::to_string(k) + "]"));
  }
  plane.source = static_cast<std::int32_t>(reader.integer(entry, where, "source_plane", 1, kIdMax));
  plane.candidates = static_cast<std::int32_t>(reader.integer(entry, where, "candidates", 0, kIdMax));
  return plane;
}

}  // namespace

PlaneDetection parsePlanesJson(std::string_view text, const std::string& name) {
  const Reader reader(name);
  json document;
  try {
    document = json::parse(text);
  } catch (const json::exception& error) {
    // parse_error, or out_of_range for a number like 1e999; the message carries the byte.
    throw Error(name + ": not valid JSON: " + error.what());
  }
  const json& schema = reader.member(document, "top level", "schema");
  if (!schema.is_string() || schema.get<std::string>() != kPlanesSchema) {
    reader.fail("schema", std::string("expected \"") + kPlanesSchema + "\", found " + schema.dump());
  }
  PlaneDetection detection;
  detection.config = readParameters(reader, reader.member(document, "top level", "parameters"));

  const json& run = reader.member(document, "top level", "detection");
  constexpr std::int64_t kCountMax = std::numeric_limits<std::int64_t>::max();
  ErmsmStats& stats = detection.stats;
  stats.candidates = static_cast<std::size_t>(reader.integer(run, "detection", "candidates", 0, kCountMax));
  stats.scored = static_cast<std::size_t>(reader.integer(run, "detection", "scored", 0, kCountMax));
  stats.accepted = static_cast<std::size_t>(reader.integer(run, "detection", "accepted", 0, kCountMax));
  stats.labelled_blocks = static_cast<std::size_t>(reader.integer(run, "detection", "labelled_blocks", 0, kCountMax));
  stats.blocks_with_direction =
      static_cast<std::size_t>(reader.integer(run, "detection", "blocks_with_direction", 0, kCountMax));
  // Files written before the count was kept ran one pass or did not say.
  if (run.contains("passes")) stats.passes = static_cast<int>(reader.integer(run, "detection", "passes", 1, 3));
  const json& parameters = reader.member(document, "top level", "parameters");
  if (parameters.contains("assumed_noise")) stats.prior_noise = reader.number(parameters, "parameters", "assumed_noise");
  const json& timings = reader.member(document, "top level", "timings");
  stats.direction_seconds = reader.number(timings, "timings", "direction_vectors_s");
  stats.detection_seconds = reader.number(timings, "timings", "detection_s");
  if (document.contains("map") && document["map"].is_object() && document["map"].contains("blocks")) {
    stats.blocks = static_cast<std::size_t>(reader.integer(document["map"], "map", "blocks", 0, kCountMax));
  }

  const json& planes = reader.member(document, "top level", "planes");
  if (!planes.is_array()) reader.fail("planes", "expected an array");
  std::set<std::int32_t> ids;
  detection.planes.reserve(planes.size());
  for (std::size_t k = 0; k < planes.size(); ++k) {
    const std::string where = "planes[" + std::to_string(k) + "]";
    Plane plane = readPlane(reader, planes[k], where);
    if (!ids.insert(plane.id).second) reader.fail(where + ".id", "id " + std::to_string(plane.id) + " appears twice");
    detection.planes.push_back(std::move(plane));
  }
  return detection;
}

PlaneDetection readPlanesJson(const std::filesystem::path& path) {
  return parsePlanesJson(readWholeFile(path), path.string());
}

}  // namespace mlmap::io
