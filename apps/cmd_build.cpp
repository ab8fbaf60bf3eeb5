// mlmap build: scans + poses -> an .mlmap file (both layers).
#include <chrono>
#include <cstdio>

#include "commands.hpp"
#include "mlmap/io/map_file.hpp"
#include "mlmap/io/tum_poses.hpp"
#include "mlmap/map/map.hpp"
#include "mlmap/registration/floor_calibration.hpp"
#include "mlmap/registration/sequence_registration.hpp"
#include "posed_scans.hpp"
#include "progress.hpp"

namespace mlmap::cli {
namespace {

struct BuildOptions {
  std::string output;
  std::string poses;
  std::vector<std::string> scans;
  MapConfig map;
  bool no_octree = false;
  double range_sigma = 0.0;
  bool register_scans = false;  // correct the poses by ICP before building
  std::string mount;            // from `mlmap calibrate`: roll/pitch applied to sensor-frame points
};

// --register: one pass over the scans for scan-to-map ICP and the pose graph, from the
// given poses (odometry) or each scan's own; returns one corrected pose per scan.
std::vector<io::StampedPose> registeredPoses(const BuildOptions& options, std::vector<io::StampedPose> poses,
                                             const registration::MountCorrection& mount, bool quiet) {
  registration::SequenceRegistration sequence;
  std::vector<io::StampedPose> corrected;
  Progress progress("register", options.scans.size(), !quiet);
  forEachPosedScan(
      options.scans, poses, options.poses,
      [&](Scan& scan, std::size_t index, std::size_t file) {
        registration::applyMountCorrection(scan, mount);
        corrected.push_back(poses.empty() ? io::StampedPose{static_cast<double>(index), scan.pose} : poses[index]);
        const registration::IcpResult result = sequence.addScan(scan.points, scan.pose);
        if (result.unreliable && !quiet) {
          std::fprintf(stderr, "register: scan %zu (%s) is unreliable: %zu inliers%s\n", index,
                       options.scans[file].c_str(), result.inliers, result.degenerate ? ", degenerate geometry" : "");
        }
      },
      [&](std::size_t file) { progress.update(file + 1); });
  sequence.refine();
  progress.finish();
  for (std::size_t i = 0; i < corrected.size(); ++i) corrected[i].pose = sequence.poses()[i];
  return corrected;
}

int runBuild(const BuildOptions& options, bool quiet) {
  std::vector<io::StampedPose> poses;
  if (!options.poses.empty()) poses = io::readTumPoses(options.poses);
  registration::MountCorrection mount;
  if (!options.mount.empty()) mount = registration::readMountCorrection(options.mount);
  if (options.register_scans) poses = registeredPoses(options, poses, mount, quiet);

  MapConfig config = options.map;
  config.with_octree = !options.no_octree;
  Map map(config);
  const auto start = std::chrono::steady_clock::now();
  Progress progress("build", options.scans.size(), !quiet);
  std::size_t scan_count = 0;
  std::size_t point_count = 0;
  forEachPosedScan(
      options.scans, poses, options.poses,
      [&](Scan& scan, std::size_t, std::size_t) {
        if (!options.mount.empty()) registration::applyMountCorrection(scan, mount);
        if (scan.variances.empty() && options.range_sigma > 0.0) {
          scan.variances.assign(scan.size(), options.range_sigma * options.range_sigma);
        }
        map.insertScan(scan);
        ++scan_count;
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
              options.output.c_str(), scan_count, point_count, stats.cells, stats.blocks,
              stats.horizontal_blocks, stats.vertical_blocks, config.cell_size, seconds);
  return 0;
}

}  // namespace

void addBuildCommand(CLI::App& app, Context& context) {
  auto options = std::make_shared<BuildOptions>();
  auto* command = app.add_subcommand(
      "build", "Build an ML map (blocks + OcTree) from scans and their poses");
  command->add_option("-o,--output", options->output, "Map file to write (.mlmap)")->required();
  command->add_option("--poses", options->poses,
                      "TUM pose file, one pose per scan in order (scan i in the sensor frame, pose i "
                      "maps it to the world); without it each scan's own pose is used");
  command->add_option("--cell-size", options->map.cell_size, "ML-map cell size, m")
      ->default_val(0.1)
      ->check(CLI::PositiveNumber);
  command->add_option("--octree-resolution", options->map.octree_resolution,
                      "OcTree voxel size, m (default: the cell size)")
      ->check(CLI::NonNegativeNumber);
  command->add_option("--max-range", options->map.max_range,
                      "Cut OcTree rays at this range, m (default: no limit)");
  command->add_flag("--no-octree", options->no_octree, "Build the block layer only");
  command->add_flag("--exact-rays", options->map.exact_rays,
                    "One OcTree ray per point (OctoMap's insertPointCloud with discretize = false); "
                    "default: one ray to the centre of each voxel holding end points (discretize = true)");
  command->add_option("--range-sigma", options->range_sigma,
                      "Range noise of scans that carry no per-point variance, m "
                      "(default: the UTM-30LX's 0.03)")
      ->check(CLI::PositiveNumber);
  command->add_flag("--register", options->register_scans,
                    "Correct the poses (--poses as odometry, else each scan's own) by scan-to-map ICP "
                    "and a pose graph first, as `mlmap register` does");
  command->add_option("--mount", options->mount,
                      "Tilt correction (the JSON `mlmap calibrate` writes) applied to every scan")
      ->check(CLI::ExistingFile);
  command->add_option("scans", options->scans,
                      "Scan files: .xyz .txt .pts .ply .pcd .3d (3DTK) .graph (OctoMap)")
      ->required()
      ->check(CLI::ExistingFile);
  command->callback([options, &context] {
    context.run = [options, &context] { return runBuild(*options, context.quiet); };
  });
}

}  // namespace mlmap::cli
