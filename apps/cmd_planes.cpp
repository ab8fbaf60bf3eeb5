// mlmap planes: eRMSM plane detection on a map's blocks; labels, JSON export.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "commands.hpp"
#include "mlmap/io/map_file.hpp"
#include "mlmap/io/planes_json.hpp"
#include "mlmap/planes/classify.hpp"
#include "mlmap/map/map_planes.hpp"
#include "number_options.hpp"
#include "output_check.hpp"

namespace mlmap::cli {
namespace {


struct PlanesArguments {
  std::string map;
  std::string json;
  std::string output;
  ErmsmConfig config;
};

int runPlanes(const PlanesArguments& arguments, bool quiet) {
  if (!arguments.json.empty()) checkWritable(arguments.json);
  if (!arguments.output.empty()) checkWritable(arguments.output);
  Map map = io::readMap(arguments.map);
  const std::size_t blocks = map.blocks().blockCount();
  if (!quiet) std::fprintf(stderr, "planes: %zu blocks ...\n", blocks);
  const PlaneDetection& detection = detectPlanes(map, arguments.config);
  if (!arguments.json.empty()) io::writePlanesJson(arguments.json, map, detection, arguments.map);
  // The map carries its planes, so `mlmap export` needs no second detection run.
  if (!arguments.output.empty()) io::writeMap(arguments.output, map);
  const ErmsmStats& stats = detection.stats;
  // The map's blocks, labelled ones included (eRMSM joins a cell's stacked blocks into
  // fewer of its own: the JSON's detection.blocks).
  std::printf("%s: %zu blocks, %zu of them labelled (%.1f %%); %zu planes (%zu patches) from %zu candidates in "
              "%.3f s (direction vectors %.3f s, detection %.3f s)\n",
              arguments.map.c_str(), blocks, stats.labelled_blocks,
              blocks == 0 ? 0.0 : 100.0 * static_cast<double>(stats.labelled_blocks) / static_cast<double>(blocks),
              stats.accepted, detection.planes.size(), stats.candidates,
              stats.direction_seconds + stats.detection_seconds, stats.direction_seconds, stats.detection_seconds);
  // The parameters the run used, resolved ones (ε, σ) included: the JSON has them all.
  const ErmsmConfig& used = detection.config;
  // σ measured on a first pass's planes says what the build assumed.
  char assumed[80] = "";
  if (stats.prior_noise > 0.0) std::snprintf(assumed, sizeof assumed, " (measured; %.4f m assumed)", stats.prior_noise);
  // A plane may widen its ε up to max_epsilon where its own blocks spread more.
  char widest[48] = "";
  if (used.max_epsilon > used.epsilon) std::snprintf(widest, sizeof widest, " (a plane's up to %.3f m)", used.max_epsilon);
  std::printf("  parameters: r %d cells, ε %.3f m%s, σ %.4f m%s, κ %g°, θ %g°, p_t %g, s_m %g m², "
              "Max_cp %d, seed %llu\n",
              used.radius, used.epsilon, widest, used.noise, assumed, used.kappa_deg, used.theta_deg, used.min_probability,
              used.min_area, used.max_candidates, static_cast<unsigned long long>(used.seed));
  const ErmsmStageSeconds& stage = stats.stages;
  std::printf("  stages (s): noise %.3f, blocks %.3f, directions %.3f, index %.3f, search %.3f, patches %.3f, "
              "merges %.3f, labels %.3f\n",
              stage.noise, stage.grid, stage.directions, stage.index, stage.search, stage.patches, stage.merges,
              stage.labels);
  std::printf("  %4s %-8s %8s %8s %7s %26s %8s %8s\n", "id", "class", "area m²", "blocks", "rms cm",
              "normal", "offset", "cands");
  for (const Plane& plane : detection.planes) {
    std::printf("  %4d %-8s %8.2f %8zu %7.2f  (%6.3f, %6.3f, %6.3f) %8.3f %8d\n", plane.id,
                std::string(className(plane.label)).c_str(), plane.area, plane.block_count,
                100.0 * plane.rms, plane.normal.x(), plane.normal.y(), plane.normal.z(),
                plane.offset - plane.normal.dot(map.config().origin), plane.candidates);  // the world's
  }
  // Classes are heights above the floor: say when there is none to measure from (a cloud
  // cut above its floor), rather than leave a user to wonder why no table is a table.
  const bool level = std::any_of(detection.planes.begin(), detection.planes.end(),
                                 [](const Plane& plane) { return isLevel(plane.normal); });
  const HeightReference& reference = detection.stats.height_reference;
  if (!quiet && level && reference.kind == HeightReference::Kind::WallsFoot) {
    std::fprintf(stderr,
                 "note: no floor in view (the map reaches well below its lowest level patch): tables and the ceiling "
                 "are measured from where the walls end below, z %.2f m; no patch is classed floor\n",
                 reference.height + map.config().origin.z());
  } else if (!quiet && level && reference.kind == HeightReference::Kind::None) {
    std::fprintf(stderr, "note: no floor in view (the map reaches well below its lowest level patch), and no two "
                         "walls end at one height: no patch is classed floor, ceiling or table\n");
  }
  // A wall's worth of blocks left out by the direction-spread rule: a room's wall (on the
  // real scans of ../shared/data the largest such refusals are 0.3-4 m², but for 3DTK's
  // curved hall arches at 0.05 m, 13.6 m²; make_scene.py's room with 3 cm of noise at 0.1 m:
  // 50 m², three walls).
  constexpr double kWallWorth = 10.0;  // m²
  if (!quiet && detection.stats.refused_wall_area >= kWallWorth) {
    std::fprintf(stderr,
                 "note: a wall-like plane whose blocks cover %.1f m² was refused: their directions spread %.1f° against "
                 "--max-spread %g (a curved wall does that, and so does a dense wall whose noise, σ %.1f cm here, is a "
                 "good part of a %g m cell)\n",
                 detection.stats.refused_wall_area, detection.stats.refused_wall_spread_deg,
                 detection.config.max_direction_spread_deg, 100.0 * detection.config.noise, map.blocks().cellSize());
  }
  return 0;
}

}  // namespace

void addPlanesCommand(CLI::App& app, Context& context) {
  auto arguments = std::make_shared<PlanesArguments>();
  ErmsmConfig& config = arguments->config;
  auto* command = app.add_subcommand("planes", "Detect planes in a map (eRMSM) and label its blocks");
  command->add_option("map", arguments->map, "Map file (.mlmap)")->required()->check(CLI::ExistingFile);
  command->add_option("--json", arguments->json, "Write the planes (schema mlmap.planes/1)");
  command->add_option("-o,--output", arguments->output, "Write the map with its blocks labelled");
  command->add_option("--seed", config.seed, "Random seed (same seed, same planes)")->capture_default_str();
  addNumber(command, "--threads", config.threads, "Threads (default: all cores)", 0, Bound::Closed);
  addNumber(command, "--radius", config.radius,
            "r: neighbourhood radius, cells (default 0: 2, and 1 where a cell is wider than 0.1 m: the window "
            "reaches at most 0.2 m out)",
            0, Bound::Closed, 50)
      ->capture_default_str();
  addNumber(command, "--epsilon", config.epsilon,
            "ε: max block-plane distance, m (default: max(3 σ, min(cell size, 0.05)); maps without point moments: max(cell size, min(3 σ, 0.05)))", 0.0, Bound::Closed, 10.0);
  addNumber(command, "--noise", config.noise, "σ: range noise of the map's points, m (default: the blocks' own, then measured on the planes found with it)",
            0.0, Bound::Closed, 10.0);
  addNumber(command, "--stack-gap", config.stack_gap, "A cell's blocks closer than this are one eRMSM block, m", 0.0,
            Bound::Closed)
      ->capture_default_str();
  addNumber(command, "--ladder-gap", config.ladder_gap,
            "A ladder of short blocks of a cell less than this apart is one eRMSM block (sparse scan lines), m; 0 = off",
            0.0, Bound::Closed)
      ->capture_default_str();
  addNumber(command, "--ladder-blocks", config.ladder_blocks, "Blocks a ladder needs at least", 2, Bound::Closed, 1000)
      ->capture_default_str();
  addNumber(command, "--kappa", config.kappa_deg, "κ: max angle block direction / plane normal, deg", 0.0, Bound::Open,
            90.0)
      ->capture_default_str();
  addNumber(command, "--theta", config.theta_deg, "θ: max angle between the seeds' directions, deg", 0.0, Bound::Open,
            90.0)
      ->capture_default_str();
  addNumber(command, "--probability", config.min_probability, "p_t: acceptance probability (eq. 10)", 0.0, Bound::Open,
            1.0)
      ->capture_default_str();
  addNumber(command, "--acceptance-exponent", config.acceptance_exponent,
            "k of eq. 10, P = (s_c/s_o)^k: the paper's 3, or 1 (default: only the first seed is drawn from the whole map)",
            0.0, Bound::Open, 10.0)
      ->capture_default_str();
  addNumber(command, "--min-area", config.min_area, "s_m: minimal plane surface, m²", 0.0, Bound::Closed)
      ->capture_default_str();
  addNumber(command, "--min-patch-area", config.min_patch_area, "Smaller connected patches are dropped, m²", 0.0,
            Bound::Closed)
      ->capture_default_str();
  addNumber(command, "--max-radius", config.max_radius,
            "Widest direction window where r cells leave a level block's direction uncertain, cells (0: 2 r; r: never wider)",
            0, Bound::Closed, 50.0)
      ->capture_default_str();
  addNumber(command, "--max-spread", config.max_direction_spread_deg,
            "Mean angle of a plane's blocks' directions to its normal (level planes: beyond their noise), deg", 0.0,
            Bound::Open, 90.0)
      ->capture_default_str();
  addNumber(command, "--sparse-gap", config.sparse_gap,
            "Blocks of a surface's sparse parts (no direction) join its patch across gaps up to this, and sparse surfaces no patch reached are searched with neighbourhoods of it, m; 0 = off", 0.0,
            Bound::Closed, 10.0)
      ->capture_default_str();
  addNumber(command, "--max-candidates", config.max_candidates, "Max_cp: candidates in all", 1, Bound::Closed)
      ->capture_default_str();
  addNumber(command, "--max-idle-candidates", config.max_idle_candidates,
            "Stop after this many candidates without an accepted plane", 1, Bound::Closed)
      ->capture_default_str();
  command->callback([arguments, &context] {
    context.run = [arguments, &context] { return runPlanes(*arguments, context.quiet); };
  });
}

}  // namespace mlmap::cli
