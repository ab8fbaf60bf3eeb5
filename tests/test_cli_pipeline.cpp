// The CLI from a labelled map to every export, and merge: with a transform, by
// registration, and refused when the maps do not overlap; label, point by point.
#include <doctest/doctest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "helpers.hpp"
#include "json_schema.hpp"
#include "mlmap/io/dashboard.hpp"
#include "mlmap/io/dashboard_blocks.hpp"
#include "mlmap/io/map_file.hpp"
#include "mlmap/io/tum_poses.hpp"
#include "mlmap/io/xyz.hpp"
#include "room_scenes.hpp"

using mlmap::test::runCli;
namespace fs = std::filesystem;

namespace {

struct RoomMaps {
  mlmap::test::TempDir dir;
  fs::path map;       // all scans, true poses
  fs::path west;      // scans 0 and 1
  fs::path east;      // scans 2 and 3

  RoomMaps() {
    mlmap::test::writeText(dir / "rooms.json", mlmap::test::kRoomsJson);
    auto result = runCli("--quiet simulate " + (dir / "rooms.json").string() + " -o " + (dir / "sim").string());
    REQUIRE_MESSAGE(result.exit_code == 0, result.output);
    const auto scan = [&](int k) { return (dir / "sim" / ("scan_00" + std::to_string(k) + ".xyz")).string(); };
    const std::string poses = (dir / "sim" / "poses_true.txt").string();
    map = dir / "rooms.mlmap";
    west = dir / "west.mlmap";
    east = dir / "east.mlmap";
    // Each build takes scan k with pose k of its pose file, so each half gets its own.
    std::ifstream in(poses);
    std::string line;
    std::vector<std::string> lines;
    while (std::getline(in, line)) {
      if (!line.empty() && line[0] != '#') lines.push_back(line);
    }
    REQUIRE(lines.size() == 4);
    mlmap::test::writeText(dir / "west_poses.txt", lines[0] + "\n" + lines[1] + "\n");
    mlmap::test::writeText(dir / "east_poses.txt", lines[2] + "\n" + lines[3] + "\n");
    for (const auto& [output, arguments] :
         {std::pair{map, "--poses " + poses + " " + scan(0) + " " + scan(1) + " " + scan(2) + " " + scan(3)},
          std::pair{west, "--poses " + (dir / "west_poses.txt").string() + " " + scan(0) + " " + scan(1)},
          std::pair{east, "--poses " + (dir / "east_poses.txt").string() + " " + scan(2) + " " + scan(3)}}) {
      result = runCli("--quiet build --cell-size 0.05 --max-range 12 -o " + output.string() + " " + arguments);
      REQUIRE_MESSAGE(result.exit_code == 0, result.output);
    }
  }

  // `mlmap planes -o`: the whole map with its blocks labelled.
  fs::path labelled() const {
    const fs::path output = dir / "labelled.mlmap";
    const auto result = runCli("--quiet planes " + map.string() + " -o " + output.string());
    REQUIRE_MESSAGE(result.exit_code == 0, result.output);
    return output;
  }
};

}  // namespace

TEST_CASE("CLI: planes -o keeps the planes in the map, and export writes every format") {
  RoomMaps rooms;
  const fs::path labelled = rooms.labelled();
  REQUIRE(mlmap::io::readMap(labelled).planes().has_value());
  // The summary says which parameters the run used, the resolved ε and σ among them.
  const auto printed = runCli("--quiet planes " + rooms.map.string() + " --seed 7 --kappa 20");
  REQUIRE_MESSAGE(printed.exit_code == 0, printed.output);
  // The build assumed 3 cm of range noise (points from a file), ε = 3 σ; the planes then
  // measure the points' own (0.5 cm here) and say so. ε follows it (at least a cell);
  // a plane whose blocks spread more widens its own up to the ε of the assumed σ.
  CHECK_MESSAGE(printed.output.find("parameters: r 2 cells, ε 0.050 m (a plane's up to 0.090 m), σ 0.00") != std::string::npos,
                printed.output);
  CHECK_MESSAGE(printed.output.find(" m (measured; 0.0300 m assumed)") != std::string::npos, printed.output);
  CHECK_MESSAGE(printed.output.find("κ 20°, θ 15°") != std::string::npos, printed.output);
  CHECK_MESSAGE(printed.output.find("seed 7\n") != std::string::npos, printed.output);

  mlmap::test::writeText(rooms.dir / "page.html", "<!doctype html><title>dashboard</title>");
  const fs::path out = rooms.dir / "out";
  fs::create_directories(out);
  auto result = runCli("--quiet export " + labelled.string() + " --octovis " + (out / "m.ot").string() + " --bt " +
                  (out / "m.bt").string() + " --ply " + (out / "m.ply").string() + " --json " +
                  (out / "m.json").string() + " --dashboard " + (out / "web").string() + " --dashboard-page " +
                  (rooms.dir / "page.html").string());
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  for (const char* name : {"m.ot", "m.bt", "m.ply", "m.json", "web/index.html", "web/planes.json", "web/planes.js",
                           "web/blocks.bin", "web/blocks.js"}) {
    CHECK_MESSAGE(fs::file_size(out / name) > 0, name);
  }
  std::ifstream schema_file(mlmap::test::sourceDir() / "web" / "planes.schema.json");
  const mlmap::test::JsonSchema schema(nlohmann::json::parse(schema_file));
  const nlohmann::json exported = nlohmann::json::parse(mlmap::test::readText(out / "m.json"));
  const auto error = schema.check(exported);
  CHECK_MESSAGE(!error.has_value(), error.value_or(""));
  CHECK(exported["planes"].size() == mlmap::io::readMap(labelled).planes()->planes.size());
  CHECK(mlmap::test::readText(out / "web" / "planes.json") == mlmap::test::readText(out / "m.json"));
  CHECK(mlmap::test::readText(out / "web" / "planes.js").rfind("window.MLMAP_PLANES = {", 0) == 0);
  // The blocks layer: every block of the map, labelled with the ids of the JSON's planes.
  const std::string blocks_bytes = mlmap::test::readText(out / "web" / "blocks.bin");
  const mlmap::io::DashboardBlocks blocks = mlmap::io::parseDashboardBlocks(blocks_bytes, "blocks.bin");
  CHECK(blocks.blocks.size() == mlmap::io::readMap(labelled).blocks().blockCount());
  std::set<std::int64_t> plane_ids;
  for (const auto& plane : exported["planes"]) plane_ids.insert(plane["id"].get<std::int64_t>());
  std::size_t labelled_blocks = 0;
  for (const auto& block : blocks.blocks) {
    if (block.plane == 0) continue;
    ++labelled_blocks;
    CHECK_MESSAGE(plane_ids.count(block.plane) == 1, block.plane);
  }
  CHECK(labelled_blocks > blocks.blocks.size() / 2);
  CHECK(mlmap::test::readText(out / "web" / "blocks.js") ==
        "window.MLMAP_BLOCKS = \"" + mlmap::io::base64(blocks_bytes) + "\";\n");

  // Without a page, --dashboard fails at once and writes nothing.
  result = runCli("--quiet export " + labelled.string() + " --dashboard " + (out / "web2").string() +
                  " --dashboard-page " + (rooms.dir / "missing.html").string());
  CHECK(result.exit_code == 1);
  CHECK(result.output.find("missing.html") != std::string::npos);
  CHECK_FALSE(fs::exists(out / "web2"));
  CHECK(runCli("export " + labelled.string()).output.find("nothing to export") != std::string::npos);
}

TEST_CASE("CLI: merge with a transform, by registration, and refused without overlap") {
  RoomMaps rooms;
  const fs::path merged = rooms.dir / "merged.mlmap";
  auto result = runCli("merge " + rooms.west.string() + " " + rooms.east.string() + " --register -o " +
                       merged.string());
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  CHECK(result.output.find("blocks:") != std::string::npos);
  const auto merged_blocks = mlmap::io::readMap(merged).blocks().blockCount();
  const auto direct_blocks = mlmap::io::readMap(rooms.map).blocks().blockCount();
  CHECK(static_cast<double>(merged_blocks) < 1.15 * static_cast<double>(direct_blocks));

  // The east map built 40 m away (its poses moved along x): ICP from the identity finds
  // nothing to match. (A map merged into west at +40 m would hold west itself at the identity.)
  std::ifstream east_poses(rooms.dir / "east_poses.txt");
  std::string far_poses;
  for (std::string line; std::getline(east_poses, line);) {
    std::istringstream fields(line);
    double stamp = 0.0;
    double x = 0.0;
    fields >> stamp >> x;
    std::string rest;
    std::getline(fields, rest);
    far_poses += std::to_string(stamp) + " " + std::to_string(x + 40.0) + rest + "\n";
  }
  mlmap::test::writeText(rooms.dir / "far_poses.txt", far_poses);
  const fs::path far = rooms.dir / "far.mlmap";
  const auto east_scan = [&](int k) { return (rooms.dir / "sim" / ("scan_00" + std::to_string(k) + ".xyz")).string(); };
  result = runCli("--quiet build --cell-size 0.05 --max-range 12 --no-octree -o " + far.string() + " --poses " +
                  (rooms.dir / "far_poses.txt").string() + " " + east_scan(2) + " " + east_scan(3));
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  const fs::path refused = rooms.dir / "refused.mlmap";
  result = runCli("--quiet merge " + rooms.west.string() + " " + far.string() + " --register -o " + refused.string());
  CHECK(result.exit_code == 1);
  CHECK(result.output.find("unreliable") != std::string::npos);
  CHECK_FALSE(fs::exists(refused));

  mlmap::test::writeText(rooms.dir / "bad.txt", "1 2 three 4\n");
  result = runCli("--quiet merge " + rooms.west.string() + " " + rooms.east.string() + " --transform " +
                  (rooms.dir / "bad.txt").string() + " -o " + refused.string());
  CHECK(result.exit_code == 1);
  CHECK(result.output.find("bad.txt:1") != std::string::npos);
}

namespace {

// Of the points with a patch, the share whose true plane is the one most of their
// patch's points lie on: 1 when every patch holds points of one surface only.
double labelPurity(const std::vector<std::int32_t>& predicted, const std::vector<std::int32_t>& truth) {
  const mlmap::test::LabelAgreement agreement = mlmap::test::labelAgreement(predicted, truth);
  return agreement.labelled == 0 ? 0.0
                                 : static_cast<double>(agreement.on_majority) / static_cast<double>(agreement.labelled);
}

}  // namespace

TEST_CASE("CLI: label writes every scan point in order with its patch, refined on the patches' planes") {
  RoomMaps rooms;
  const fs::path labelled = rooms.labelled();
  std::string scans;
  std::vector<std::int32_t> truth;
  std::vector<mlmap::Scan> inputs;
  for (int k = 0; k < 4; ++k) {
    const fs::path scan = rooms.dir / "sim" / ("scan_00" + std::to_string(k) + ".xyz");
    scans.append(" ").append(scan.string());  // (" " + string trips g++ 12's -Wrestrict)
    inputs.push_back(mlmap::io::readXyz(scan));
    truth.insert(truth.end(), inputs.back().labels.begin(), inputs.back().labels.end());
  }
  const std::string poses = (rooms.dir / "sim" / "poses_true.txt").string();
  const fs::path refined = rooms.dir / "refined.xyz";
  const fs::path by_block = rooms.dir / "blocks.xyz";
  auto result = runCli("--quiet label " + labelled.string() + " --poses " + poses + " -o " + refined.string() + scans);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);
  result = runCli("--quiet label --block-labels " + labelled.string() + " --poses " + poses + " -o " +
                  by_block.string() + scans);
  REQUIRE_MESSAGE(result.exit_code == 0, result.output);

  const mlmap::Scan points = mlmap::io::readXyz(refined);
  const mlmap::Scan block_points = mlmap::io::readXyz(by_block);
  REQUIRE(points.size() == truth.size());
  REQUIRE(block_points.size() == truth.size());
  // Input order, world frame: the first scan's first point, moved by its true pose.
  const mlmap::Point first = mlmap::io::readTumPoses(poses).at(0).pose * inputs[0].points[0];
  CHECK((points.points[0] - first).norm() < 1e-4);
  const auto patches = mlmap::io::readMap(labelled).planes()->planes.size();
  std::size_t with_patch = 0;
  for (const std::int32_t label : points.labels) {
    CHECK((label == -1 || (label >= 1 && static_cast<std::size_t>(label) <= patches)));
    with_patch += label > 0 ? 1 : 0;
  }
  CHECK(static_cast<double>(with_patch) > 0.9 * static_cast<double>(points.size()));
  // Edge blocks hold points of two surfaces; the refinement gives them back.
  const double purity = labelPurity(points.labels, truth);
  const double block_purity = labelPurity(block_points.labels, truth);
  CHECK(purity > 0.995);
  CHECK(purity > block_purity);
}
