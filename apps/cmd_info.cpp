// mlmap info: what a map file holds.
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>

#include "commands.hpp"
#include "mlmap/io/map_file.hpp"

namespace mlmap::cli {
namespace {

int runInfo(const std::string& path, bool as_json) {
  // The OcTree section is counted, not built: a large map's tree took seconds to allocate.
  const io::MapSummary summary = io::readMapSummary(path);
  const Map& map = summary.map;
  const MLMapStats& stats = summary.blocks;
  nlohmann::json info;
  info["file"] = path;
  info["file_bytes"] = std::filesystem::file_size(path);
  info["cell_size"] = map.config().cell_size;
  info["cells"] = stats.cells;
  info["blocks"] = {{"total", stats.blocks},
                    {"horizontal", stats.horizontal_blocks},
                    {"vertical", stats.vertical_blocks},
                    {"labelled", stats.labelled_blocks}};
  // In the world's coordinates; the map holds them moved by −origin (MapConfig::origin).
  const Eigen::Vector3d& origin = map.config().origin;
  const Eigen::Vector3d low = stats.min + origin, high = stats.max + origin;
  info["bounds"] = {{"min", {low.x(), low.y(), low.z()}}, {"max", {high.x(), high.y(), high.z()}}};
  if (!origin.isZero()) info["origin"] = {origin.x(), origin.y(), origin.z()};
  info["memory_bytes"] = {{"blocks", stats.memory_bytes}};
  const double bytes_per_block =
      stats.blocks == 0 ? 0.0 : static_cast<double>(stats.memory_bytes) / static_cast<double>(stats.blocks);
  if (summary.octree) {
    const io::OctreeSummary& tree = *summary.octree;
    info["octree"] = {{"resolution", tree.resolution},
                      {"nodes", tree.nodes},
                      {"leaves", tree.leaves},
                      {"occupied_leaves", tree.occupied_leaves},
                      {"free_leaves", tree.leaves - tree.occupied_leaves}};
    info["memory_bytes"]["octree"] = tree.memory_bytes;
  }
  // Planes by class, when the map is labelled (mlmap planes -o).
  struct ClassTotal {
    std::size_t patches = 0;
    double area = 0.0;
  };
  std::map<std::string, ClassTotal> by_class;
  if (map.planes()) {
    for (const Plane& plane : map.planes()->planes) {
      ClassTotal& total = by_class[std::string(className(plane.label))];
      ++total.patches;
      total.area += plane.area;
    }
    nlohmann::json classes = nlohmann::json::object();
    for (const auto& [name, total] : by_class) classes[name] = {{"patches", total.patches}, {"area", total.area}};
    info["planes"] = {{"patches", map.planes()->planes.size()},
                      {"by_class", classes},
                      {"detection_s", map.planes()->stats.direction_seconds + map.planes()->stats.detection_seconds}};
  }
  if (as_json) {
    std::cout << info.dump(2) << "\n";
    return 0;
  }
  std::printf("%s (%.1f MB)\n", path.c_str(), static_cast<double>(info["file_bytes"]) / 1e6);
  std::printf("  cell size      %.3g m\n", map.config().cell_size);
  std::printf("  cells          %zu\n", stats.cells);
  std::printf("  blocks         %zu (%zu horizontal, %zu vertical, %zu labelled)\n", stats.blocks,
              stats.horizontal_blocks, stats.vertical_blocks, stats.labelled_blocks);
  if (!origin.isZero())
    std::printf("  origin         (%.2f, %.2f, %.2f) m: the map's frame in the scans' (its OcTree and block "
                "exports are in the map's frame)\n", origin.x(), origin.y(), origin.z());
  std::printf("  bounds         x %.2f..%.2f  y %.2f..%.2f  z %.2f..%.2f m\n", low.x(), high.x(), low.y(),
              high.y(), low.z(), high.z());
  std::printf("  block memory   %.1f MB (%.1f bytes/block)\n", static_cast<double>(stats.memory_bytes) / 1e6,
              bytes_per_block);
  if (summary.octree) {
    const auto& octree = info["octree"];
    std::printf("  OcTree         %.3g m, %zu nodes, %zu leaves (%zu occupied, %zu free), %.1f MB\n",
                static_cast<double>(octree["resolution"]), static_cast<std::size_t>(octree["nodes"]),
                static_cast<std::size_t>(octree["leaves"]),
                static_cast<std::size_t>(octree["occupied_leaves"]),
                static_cast<std::size_t>(octree["free_leaves"]),
                static_cast<double>(info["memory_bytes"]["octree"]) / 1e6);
  } else {
    std::printf("  OcTree         none (built with --no-octree)\n");
  }
  if (!map.planes()) {
    std::printf("  planes         none (label the map with `mlmap planes MAP -o LABELLED.mlmap`)\n");
    return 0;
  }
  std::printf("  planes         %zu patches, detected in %.3f s\n", map.planes()->planes.size(),
              static_cast<double>(info["planes"]["detection_s"]));
  std::printf("    %-8s %8s %10s\n", "class", "patches", "area m²");
  for (const auto& [name, total] : by_class) std::printf("    %-8s %8zu %10.1f\n", name.c_str(), total.patches, total.area);
  return 0;
}

}  // namespace

void addInfoCommand(CLI::App& app, Context& context) {
  auto path = std::make_shared<std::string>();
  auto as_json = std::make_shared<bool>(false);
  auto* command = app.add_subcommand("info", "Print what a map file holds");
  command->add_option("map", *path, "Map file (.mlmap)")->required()->check(CLI::ExistingFile);
  command->add_flag("--json", *as_json, "Print JSON instead of text");
  command->callback([path, as_json, &context] {
    context.run = [path, as_json] { return runInfo(*path, *as_json); };
  });
}

}  // namespace mlmap::cli
