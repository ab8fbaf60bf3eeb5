// mlmap register: scans + odometry poses -> corrected poses (TUM), by scan-to-map ICP and
// a pose graph over overlapping pairs.
#include <chrono>
#include <cstdio>

#include "commands.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/tum_poses.hpp"
#include "mlmap/registration/sequence_registration.hpp"
#include "mlmap/registration/trajectory_error.hpp"
#include "progress.hpp"
#include "scan_options.hpp"

namespace mlmap::cli {
namespace {

struct RegisterOptions {
  std::string output;
  ScanOptions input;
  std::string reference;
  std::string metric = "point-to-plane";
  bool no_refine = false;
  registration::SequenceConfig config;
};

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void printError(const char* label, const std::vector<Pose>& poses, const std::vector<Pose>& reference) {
  const registration::TrajectoryError error = registration::trajectoryError(poses, reference);
  std::printf("%s ATE: translation RMS %.2f cm (max %.2f cm), rotation RMS %.3f deg (max %.3f deg)\n", label,
              100.0 * error.rms_translation, 100.0 * error.max_translation, error.rms_rotation_deg,
              error.max_rotation_deg);
}

int runRegister(RegisterOptions options, bool quiet) {
  options.config.icp.metric = options.metric == "point-to-point" ? registration::IcpMetric::PointToPoint
                                                                   : registration::IcpMetric::PointToPlane;
  checkWritable(options.output);
  options.input.identity = true;  // without odometry, registration starts from each scan's own pose
  const ScanReading reading(options.input, "register", quiet);
  const std::vector<io::StampedPose>& odometry = reading.sequence().poses();
  options.config.min_range = options.input.range.min;
  options.config.max_range = options.input.range.max;

  registration::SequenceRegistration sequence(options.config);
  std::vector<io::StampedPose> stamped;
  std::vector<Pose> odometry_poses;
  double register_seconds = 0.0;
  std::size_t point_count = 0;
  Progress progress("register", options.input.scans.size(), !quiet);
  reading.forEach(
      [&](Scan& scan, std::size_t index, std::size_t) {
        const io::StampedPose guess{odometry.empty() ? static_cast<double>(index) : odometry[index].stamp, scan.pose};
        const auto start = std::chrono::steady_clock::now();
        const registration::IcpResult result = sequence.addScan(scan.points, guess.pose);
        register_seconds += secondsSince(start);
        point_count += scan.size();
        stamped.push_back(guess);
        odometry_poses.push_back(guess.pose);
        if (!quiet || result.unreliable) {
          std::fprintf(stderr, "scan %zu: %zu points, %zu/%zu inliers, RMS %.2f cm, %d iterations%s%s\n", index,
                       scan.size(), result.inliers, result.source_points, 100.0 * result.rms_residual,
                       result.iterations, result.degenerate ? ", degenerate" : "",
                       result.unreliable ? ", UNRELIABLE" : "");
        }
      },
      [&](std::size_t file) { progress.update(file + 1, std::to_string(point_count) + " points"); });
  progress.finish(std::to_string(point_count) + " points");
  const std::vector<Pose> sequential = sequence.poses();

  double refine_seconds = 0.0;
  if (!options.no_refine) {
    const auto start = std::chrono::steady_clock::now();
    const registration::RefinementResult refinement = sequence.refine();
    refine_seconds = secondsSince(start);
    std::printf("refinement: %zu pair edges (%zu pairs rejected), graph cost %.4g -> %.4g in %.2f s\n",
                refinement.pair_edges, refinement.rejected_pairs, refinement.graph.initial_cost,
                refinement.graph.final_cost, refine_seconds);
  }
  for (std::size_t i = 0; i < stamped.size(); ++i) stamped[i].pose = sequence.poses()[i];
  io::writeTumPoses(options.output, stamped);
  std::printf("%s: %zu scans, %zu points; scan-to-map %.3f s per scan, refinement %.2f s\n",
              options.output.c_str(), stamped.size(), point_count,
              stamped.empty() ? 0.0 : register_seconds / static_cast<double>(stamped.size()), refine_seconds);
  if (!options.reference.empty()) {
    std::vector<Pose> reference;
    for (const io::StampedPose& pose : io::readTumPoses(options.reference)) reference.push_back(pose.pose);
    printError("odometry  ", odometry_poses, reference);
    printError("scan-to-map", sequential, reference);
    if (!options.no_refine) printError("refined   ", sequence.poses(), reference);
  }
  return 0;
}

}  // namespace

void addRegisterCommand(CLI::App& app, Context& context) {
  auto options = std::make_shared<RegisterOptions>();
  auto* command = app.add_subcommand(
      "register", "Correct odometry poses by ICP: scan-to-map, then a pose graph over overlapping pairs");
  command->add_option("-o,--output", options->output, "Corrected poses to write (TUM)")->required();
  command->add_option("--reference", options->reference,
                      "Reference poses (TUM, same world frame) to print the absolute trajectory error");
  command->add_option("--metric", options->metric, "ICP error metric")
      ->check(CLI::IsMember({"point-to-plane", "point-to-point"}))
      ->default_val("point-to-plane");
  command->add_option("--voxel-size", options->config.source_voxel_size,
                      "Down-sampling of the scan being registered, m")
      ->default_val(0.1)
      ->check(CLI::PositiveNumber);
  command->add_option("--map-voxel-size", options->config.map_voxel_size,
                      "OcTree resolution of the map's nearest-neighbour grid, m")
      ->default_val(0.1)
      ->check(CLI::PositiveNumber);
  command->add_option("--max-distance", options->config.icp.initial_max_distance,
                      "Initial correspondence distance, m: a bound on the odometry error")
      ->default_val(0.5)
      ->check(CLI::PositiveNumber);
  command->add_flag("--no-refine", options->no_refine, "Scan-to-map only, no pose graph");
  addScanOptions(command, options->input,
                 {.poses_help = "Odometry poses (TUM), one per scan in order; without it each scan's own pose",
                  .identity = false});
  command->callback([options, &context] {
    context.run = [options, &context] { return runRegister(*options, context.quiet); };
  });
}

}  // namespace mlmap::cli
