#include "mlmap/io/planes_json.hpp"

#include <nlohmann/json.hpp>

#include "file_bytes.hpp"

namespace mlmap::io {
namespace {

nlohmann::json vector3(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

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

std::string planesJson(const Map& map, const PlaneDetection& detection, const std::string& source_name) {
  const MLMapStats stats = map.blocks().stats();
  const ErmsmConfig& config = detection.config;
  nlohmann::json json;
  json["schema"] = kPlanesSchema;
  json["map"] = {{"source", source_name},
                 {"cell_size", map.config().cell_size},
                 {"cells", stats.cells},
                 {"blocks", stats.blocks},
                 {"bounds", {{"min", vector3(stats.min)}, {"max", vector3(stats.max)}}}};
  json["parameters"] = {{"radius_cells", config.radius},
                        {"epsilon", config.epsilon},
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
                        {"noise", config.noise},
                        {"stack_gap", config.stack_gap},
                        {"ladder_gap", config.ladder_gap},
                        {"ladder_blocks", config.ladder_blocks},
                        {"seed", config.seed}};
  const ErmsmStats& run = detection.stats;
  json["detection"] = {{"candidates", run.candidates},
                       {"scored", run.scored},
                       {"accepted", run.accepted},
                       {"labelled_blocks", run.labelled_blocks},
                       {"blocks_with_direction", run.blocks_with_direction}};
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
  for (const Plane& plane : detection.planes) {
    nlohmann::json outline = nlohmann::json::array();
    for (const Eigen::Vector3d& corner : plane.outline) outline.push_back(vector3(corner));
    nlohmann::json entry = {{"id", plane.id},
                            {"label", std::string(className(plane.label))},
                            {"normal", vector3(plane.normal)},
                            {"offset", plane.offset},
                            {"centroid", vector3(plane.centroid)},
                            {"area", plane.area},
                            {"blocks", plane.block_count},
                            {"rms", plane.rms},
                            {"outline", outline},
                            {"source_plane", plane.source},
                            {"candidates", plane.candidates}};
    if (const char* city = cityJsonName(plane.label)) entry["cityjson_type"] = city;
    planes.push_back(std::move(entry));
  }
  json["planes"] = std::move(planes);
  return json.dump(2) + "\n";
}

void writePlanesJson(const std::filesystem::path& path, const Map& map, const PlaneDetection& detection,
                     const std::string& source_name) {
  writeWholeFile(path, planesJson(map, detection, source_name));
}

}  // namespace mlmap::io
