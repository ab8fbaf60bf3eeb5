// mlmap export: a map for other tools — octovis (.ot, coloured by plane), OctoMap
// (.bt), point-cloud viewers (.ply of the blocks), the planes JSON and the web dashboard.

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>

#include "commands.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/block_ply.hpp"
#include "mlmap/io/dashboard.hpp"
#include "mlmap/io/dashboard_blocks.hpp"
#include "mlmap/io/dashboard_voxels.hpp"
#include "mlmap/io/map_file.hpp"
#include "mlmap/io/octree_export.hpp"
#include "mlmap/io/planes_json.hpp"

namespace mlmap::cli {
namespace {

struct ExportArguments {
  std::string map;
  std::string octovis;
  std::string binary_tree;
  std::string ply;
  std::string json;
  std::string dashboard;
  std::string dashboard_page;
  bool dashboard_voxels = false;
};

// The built dashboard: $MLMAP_DASHBOARD_PAGE, else beside the executable as in a
// build tree (build/mlmap → web/dist/index.html) or an install (bin/ → share/mlmap/).
std::filesystem::path findDashboardPage(const std::string& requested) {
  if (!requested.empty()) return requested;
  if (const char* from_environment = std::getenv("MLMAP_DASHBOARD_PAGE")) return from_environment;
  std::error_code error;
  const std::filesystem::path executable = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) {
    const std::filesystem::path prefix = executable.parent_path().parent_path();
    for (const auto& candidate : {prefix / "web" / "dist" / "index.html", prefix / "share" / "mlmap" / "index.html"}) {
      if (std::filesystem::is_regular_file(candidate)) return candidate;
    }
  }
  throw Error("the web dashboard is not built: run `bash scripts/web-build.sh`, "
              "or pass --dashboard-page web/dist/index.html");
}

int runExport(const ExportArguments& arguments, bool quiet) {
  if (arguments.octovis.empty() && arguments.binary_tree.empty() && arguments.ply.empty() &&
      arguments.json.empty() && arguments.dashboard.empty()) {
    throw Error("nothing to export: give at least one of --octovis, --bt, --ply, --json, --dashboard");
  }
  if (arguments.dashboard_voxels && arguments.dashboard.empty()) throw Error("--dashboard-voxels needs --dashboard DIR");
  // Find the page before any work, so a missing build fails at once.
  std::optional<std::filesystem::path> page;
  if (!arguments.dashboard.empty()) page = findDashboardPage(arguments.dashboard_page);

  Map map = io::readMap(arguments.map);
  if (!arguments.binary_tree.empty() && !map.hasOctree()) {
    throw Error(arguments.map + " has no OcTree (built with --no-octree): nothing for --bt");
  }
  const bool wants_planes = !arguments.json.empty() || !arguments.dashboard.empty();
  if (!map.planes() && wants_planes) {
    if (!quiet) {
      std::fprintf(stderr, "export: %s has no planes (not labelled by `mlmap planes -o`): detecting them with the "
                   "default parameters\n", arguments.map.c_str());
    }
    map.setPlanes(detectPlanes(map.blocks()));
  }
  const auto done = [&](const char* what, const std::string& path) {
    if (!quiet) std::fprintf(stderr, "export: %s → %s\n", what, path.c_str());
  };
  if (!arguments.octovis.empty()) {
    io::writeColouredOctree(arguments.octovis, map);
    done("ColorOcTree (octovis)", arguments.octovis);
  }
  if (!arguments.binary_tree.empty()) {
    io::writeBinaryOctree(arguments.binary_tree, map);
    done("OcTree (.bt)", arguments.binary_tree);
  }
  if (!arguments.ply.empty()) {
    io::writeBlocksPly(arguments.ply, map);
    done("blocks (PLY)", arguments.ply);
  }
  const std::string source = std::filesystem::path(arguments.map).filename().string();
  if (!arguments.json.empty()) {
    io::writePlanesJson(arguments.json, map, *map.planes(), source);
    done("planes JSON", arguments.json);
  }
  if (page) {
    io::writeDashboard(arguments.dashboard, *page, io::planesJson(map, *map.planes(), source, true),
                       io::dashboardBlocks(map.blocks()),
                       arguments.dashboard_voxels ? io::dashboardVoxels(map) : std::string());
    done("dashboard", (std::filesystem::path(arguments.dashboard) / "index.html").string());
  }
  return 0;
}

}  // namespace

void addExportCommand(CLI::App& app, Context& context) {
  auto arguments = std::make_shared<ExportArguments>();
  auto* command = app.add_subcommand(
      "export", "Export a map: ColorOcTree for octovis, OcTree .bt, blocks PLY, planes JSON, web dashboard");
  command->add_option("map", arguments->map, "Map file (.mlmap); unlabelled maps get planes detected")
      ->required()->check(CLI::ExistingFile);
  command->add_option("--octovis", arguments->octovis, "ColorOcTree .ot, voxels coloured by plane (octovis FILE.ot)");
  command->add_option("--bt", arguments->binary_tree, "Plain occupancy OcTree, OctoMap's binary .bt");
  command->add_option("--ply", arguments->ply, "Block centres with normal, label and colour (binary PLY)");
  command->add_option("--json", arguments->json, "Planes JSON (schema mlmap.planes/1)");
  command->add_option("--dashboard", arguments->dashboard,
                      "Directory for the web dashboard with the planes and blocks (open DIR/index.html)");
  command->add_flag("--dashboard-voxels", arguments->dashboard_voxels,
                    "Add the occupied voxels to the dashboard (those of --octovis; 16 bytes a voxel)");
  command->add_option("--dashboard-page", arguments->dashboard_page,
                      "The built dashboard page (default: web/dist/index.html beside the build)");
  command->callback([arguments, &context] {
    context.run = [arguments, &context] { return runExport(*arguments, context.quiet); };
  });
}

}  // namespace mlmap::cli
