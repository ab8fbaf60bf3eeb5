// mlmap build: scans + poses -> an .mlmap file (both layers).
#include <chrono>
#include <cstdio>

#include "commands.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/map_file.hpp"
#include "mlmap/map/map.hpp"
#include "mlmap/registration/sequence_registration.hpp"
#include "number_options.hpp"
#include "progress.hpp"
#include "scan_options.hpp"

namespace mlmap::cli {
namespace {

struct BuildOptions {
  std::string output;
  ScanOptions input;
  MapConfig map;
  bool no_octree = false;
  double range_sigma = 0.0;
  bool register_scans = false;  // correct the poses by ICP before building
  double scan_noise = 0.0;      // m, for --register: 0 = measured within each scan
  bool no_floor_level = false;  // for --register: SequenceConfig::level_from_floor off
};

// --register: one pass over the scans for scan-to-map ICP and the pose graph, from the
// given poses (odometry) or each scan's own; returns one corrected world pose per scan.
std::vector<io::StampedPose> registeredPoses(const BuildOptions& options, const ScanReading& reading, bool quiet) {
  registration::SequenceConfig config;
  if (options.scan_noise > 0.0) config.basin.noise = config.basin.source_noise = options.scan_noise;
  config.level_from_floor = !options.no_floor_level;
  registration::SequenceRegistration sequence(config);
  std::vector<io::StampedPose> corrected;
  const std::vector<io::StampedPose>& given = reading.sequence().poses();
  Progress progress("register", options.input.scans.size(), !quiet);
  reading.forEach(
      [&](Scan& scan, std::size_t index, std::size_t file) {
        corrected.push_back({given.empty() ? static_cast<double>(index) : given[index].stamp, scan.pose});
        const registration::VerifiedIcp result = sequence.addScan(scan.points, scan.pose);
        if (!result.verified && !quiet) {
          std::fprintf(stderr, "register: scan %zu (%s) is not verified: %s\n", index,
                       options.input.scans[file].c_str(), result.reason.c_str());
        }
      },
      [&](std::size_t file) { progress.update(file + 1); });
  sequence.refine();
  progress.finish();
  const std::vector<Pose> poses = sequence.poses();
  for (std::size_t i = 0; i < corrected.size(); ++i) corrected[i].pose = poses[i];
  return corrected;
}

int runBuild(const BuildOptions& options, bool quiet) {
  checkWritable(options.output);
  ScanReading reading(options.input, "build", quiet);
  if (options.register_scans) reading = reading.withPoses(registeredPoses(options, reading, quiet));

  MapConfig config = options.map;
  config.with_octree = !options.no_octree;
  Map map(config);
  const auto start = std::chrono::steady_clock::now();
  Progress progress("build", options.input.scans.size(), !quiet);
  std::size_t point_count = 0;
  const double octree_resolution = config.octree_resolution > 0.0 ? config.octree_resolution : config.cell_size;
  bool first = true;
  const io::ScanInputCounts counts = reading.forEach(
      [&](Scan& scan, std::size_t index, std::size_t file) {
        // A cloud far from the origin (a national grid's coordinates) is mapped near it: the
        // first scan sets the map's origin, stored with the map; the commands give planes
        // and points back in the world's coordinates.
        if (first) {
          map.setOrigin(chooseOrigin(scan, keyReach(octree_resolution)));
          first = false;
          if (!map.config().origin.isZero() && !quiet)
            std::fprintf(stderr, "build: the scans lie far from the origin: the map's frame has its origin at "
                                 "(%.0f, %.0f, %.0f) m (planes and labels come back in the scans' coordinates)\n",
                         map.config().origin.x(), map.config().origin.y(), map.config().origin.z());
        }
        scan.pose.pretranslate(-map.config().origin);
        // OctoMap's keys reach ±32,768 voxels: beyond, its rays are dropped without a word,
        // and a cloud in a national grid's coordinates gave an empty OcTree.
        if (const double farthest = farthestCoordinate(scan);
            config.with_octree && farthest >= keyReach(octree_resolution)) {
          char text[200];
          std::snprintf(text, sizeof(text), "lies %.0f m from the map's origin, beyond the %.0f m the OcTree's keys reach at %g m voxels",
                        farthest, keyReach(octree_resolution), octree_resolution);
          throw Error(options.input.scans[file] + " (scan " + std::to_string(index + 1) + "): it " + text +
                      " (the first scan set the origin); map the scans apart and merge the maps, or build the "
                      "block layer alone with --no-octree");
        }
        if (scan.variances.empty() && options.range_sigma > 0.0) {
          scan.variances.assign(scan.size(), options.range_sigma * options.range_sigma);
        }
        map.insertScan(scan);
        point_count += scan.size();
      },
      [&](std::size_t file) { progress.update(file + 1, std::to_string(point_count) + " points"); });
  map.compact();
  progress.finish(std::to_string(point_count) + " points");
  io::writeMap(options.output, map);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const MLMapStats stats = map.blocks().stats();
  std::printf("%s: %zu scans, %zu points -> %zu cells, %zu blocks (%zu horizontal, %zu vertical)"
              " at %.3g m cells in %.2f s\n",
              options.output.c_str(), counts.scans, counts.points, stats.cells, stats.blocks,
              stats.horizontal_blocks, stats.vertical_blocks, config.cell_size, seconds);
  return 0;
}

}  // namespace

void addBuildCommand(CLI::App& app, Context& context) {
  auto options = std::make_shared<BuildOptions>();
  auto* command = app.add_subcommand(
      "build", "Build an ML map (blocks + OcTree) from scans and their poses");
  command->add_option("-o,--output", options->output, "Map file to write (.mlmap)")->required();
  addNumber(command, "--cell-size", options->map.cell_size, "ML-map cell size, m", 0.0, Bound::Open)
      ->default_val(0.1);
  addNumber(command, "--octree-resolution", options->map.octree_resolution,
            "OcTree voxel size, m (default: the cell size)", 0.0, Bound::Closed);
  command->add_flag("--no-octree", options->no_octree, "Build the block layer only");
  command->add_flag("--exact-rays", options->map.exact_rays,
                    "One OcTree ray per point (OctoMap's insertPointCloud with discretize = false); "
                    "default: one ray to the centre of each voxel holding end points (discretize = true)");
  addNumber(command, "--range-sigma", options->range_sigma,
            "Range noise of scans that carry no per-point variance, m (default: the UTM-30LX's 0.03)", 0.0,
            Bound::Open);
  auto* register_flag = command->add_flag("--register", options->register_scans,
                    "Correct the poses (--poses as odometry, else each scan's own) by scan-to-map ICP "
                    "and a pose graph first, as `mlmap register` does");
  addNumber(command, "--scan-noise", options->scan_noise,
            "With --register: how far each scan's surfaces lie from where another scan sees them, m "
            "(as `mlmap register --scan-noise`; default: measured within each scan)",
            0.0, Bound::Open)
      ->needs(register_flag);
  command->add_flag("--no-floor-level", options->no_floor_level,
                    "With --register: never take a scan's tilt and height from its own floor (as `mlmap register "
                    "--no-floor-level`)")
      ->needs(register_flag);
  addNumber(command, "--outlier-radius", options->input.isolated.radius,
            "Drop readings with fewer than --outlier-neighbours others within this of them in their own scan, m "
            "(floating outliers of dense clouds: flying pixels, dust; far sparse readings go too; default 0: keep all)",
            0.0, Bound::Closed);
  command->add_option("--outlier-neighbours", options->input.isolated.min_neighbours,
                      "With --outlier-radius: the others a reading needs within it")
      ->default_val(2)
      ->check(CLI::Range(1, 1000));
  addScanOptions(command, options->input,
                 {.poses_help = "TUM pose file, one pose per scan in order (scan i in the sensor frame, pose i "
                                "maps it to the world); without it each scan's own pose (PCD VIEWPOINT, 3DTK "
                                ".pose, .graph)"});
  command->callback([options, &context] {
    context.run = [options, &context] { return runBuild(*options, context.quiet); };
  });
}

}  // namespace mlmap::cli
