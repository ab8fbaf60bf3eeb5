#include "mlmap/io/planes_json.hpp"

#include <algorithm>

#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>

#include "file_bytes.hpp"

namespace mlmap::io {
namespace {

nlohmann::json vector3(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

// Positions to the micrometre: far below any scan's noise, and printed short ("28.7",
// not the "28.70000000000179" of a corner lifted onto its plane), which keeps a 2 cm
// map's outlines a quarter of the size.
double toMicrometre(double metres) { return std::isfinite(metres) ? std::round(metres * 1e6) / 1e6 : metres; }
nlohmann::json position(const Eigen::Vector3d& v) {
  return nlohmann::json::array({toMicrometre(v.x()), toMicrometre(v.y()), toMicrometre(v.z())});
}
// Values the detection holds in single precision (ε, the measured noise) as the float
// they are: "0.03", not the "0.029999999329447746" of that float widened to double.
double asFloat(double value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof(text), static_cast<float>(value)).ptr;
  double shortest = value;
  std::from_chars(text, end, shortest);
  return shortest;
}

// CityJSON's names for the classes it has, for interchange.
const char* cityJsonName(PlaneClass plane_class) {
  switch (plane_class) {
    case PlaneClass::Floor: return "FloorSurface";
    case PlaneClass::Ceiling: return "CeilingSurface";
    case PlaneClass::Wall: return "InteriorWallSurface";
    default: return nullptr;
  }
}

}  // namespace

std::string planesJson(const Map& map, const PlaneDetection& detection, const std::string& source_name,
                       bool in_map_frame) {
  const MLMapStats stats = map.blocks().stats();
  const Eigen::Vector3d shift = in_map_frame ? Eigen::Vector3d::Zero() : map.config().origin;
  const ErmsmConfig& config = detection.config;
  nlohmann::json json;
  json["schema"] = kPlanesSchema;
  json["map"] = {{"source", source_name},
                 {"cell_size", map.config().cell_size},
                 {"cells", stats.cells},
                 {"blocks", stats.blocks},
                 {"bounds", {{"min", position(stats.min + shift)}, {"max", position(stats.max + shift)}}}};
  if (!map.config().origin.isZero()) json["map"]["origin"] = position(map.config().origin);
  json["parameters"] = {{"radius_cells", config.radius},
                        {"epsilon", asFloat(config.epsilon)},
                        {"max_epsilon", asFloat(std::max(config.epsilon, config.max_epsilon))},
                        {"kappa_deg", config.kappa_deg},
                        {"theta_deg", config.theta_deg},
                        {"min_probability", config.min_probability},
                        {"acceptance_exponent", config.acceptance_exponent},
                        {"min_patch_width_cells", config.min_patch_width_cells},
                        {"min_level_patch_width_cells", config.min_level_patch_width_cells},
                        {"min_area", config.min_area},
                        {"min_patch_area", config.min_patch_area},
                        {"max_candidates", config.max_candidates},
                        {"max_idle_candidates", config.max_idle_candidates},
                        {"min_patch_blocks", config.min_patch_blocks},
                        {"max_direction_spread_deg", config.max_direction_spread_deg},
                        {"batch_size", config.batch_size},
                        {"max_refits", config.max_refits},
                        {"refit_gain", config.refit_gain},
                        {"noise", asFloat(config.noise)},
                        {"stack_gap", config.stack_gap},
                        {"ladder_gap", config.ladder_gap},
                        {"ladder_blocks", config.ladder_blocks},
                        {"sparse_gap", config.sparse_gap},
                        {"seed", config.seed}};
  const ErmsmStats& run = detection.stats;
  json["detection"] = {{"candidates", run.candidates},
                       {"scored", run.scored},
                       {"accepted", run.accepted},
                       {"labelled_blocks", run.labelled_blocks},
                       {"blocks_with_direction", run.blocks_with_direction},
                       {"passes", run.passes}};
  // σ the build assumed, where the planes measured parameters.noise on a first pass.
  if (run.prior_noise > 0.0) json["parameters"]["assumed_noise"] = asFloat(run.prior_noise);
  json["timings"] = {{"direction_vectors_s", run.direction_seconds},
                     {"detection_s", run.detection_seconds},
                     {"total_s", run.direction_seconds + run.detection_seconds},
                     {"noise_s", run.stages.noise},
                     {"blocks_s", run.stages.grid},
                     {"directions_s", run.stages.directions},
                     {"index_s", run.stages.index},
                     {"search_s", run.stages.search},
                     {"patches_s", run.stages.patches},
                     {"merges_s", run.stages.merges},
                     {"labels_s", run.stages.labels}};
  nlohmann::json planes = nlohmann::json::array();
  for (const Plane& in_map : detection.planes) {
    Plane plane = in_map;
    if (!shift.isZero()) movePlane(plane, shift);
    nlohmann::json outline = nlohmann::json::array();
    for (const Eigen::Vector3d& corner : plane.outline) outline.push_back(position(corner));
    nlohmann::json entry = {{"id", plane.id},
                            {"label", std::string(className(plane.label))},
                            {"normal", vector3(plane.normal)},
                            {"offset", plane.offset},
                            {"centroid", position(plane.centroid)},
                            {"area", plane.area},
                            {"blocks", plane.block_count},
                            {"rms", plane.rms},
                            {"outline", outline},
                            {"source_plane", plane.source},
                            {"candidates", plane.candidates}};
    if (const char* city = cityJsonName(plane.label)) entry["cityjson_type"] = city;
    planes.push_back(std::move(entry));
  }
  // A member per line and a plane per line: a line-oriented tool (grep, diff) sees one
  // plane at a time, and its outline does not take a line per number.
  std::string text = "{\n";
  for (const char* key : {"schema", "map", "parameters", "detection", "timings"}) {
    text += "  \"" + std::string(key) + "\": " + json[key].dump() + ",\n";
  }
  text += "  \"planes\": [";
  for (std::size_t k = 0; k < planes.size(); ++k) text += (k == 0 ? "\n    " : ",\n    ") + planes[k].dump();
  text += planes.empty() ? "]\n}\n" : "\n  ]\n}\n";
  return text;
}

void writePlanesJson(const std::filesystem::path& path, const Map& map, const PlaneDetection& detection,
                     const std::string& source_name) {
  writeWholeFile(path, planesJson(map, detection, source_name));
}

}  // namespace mlmap::io
