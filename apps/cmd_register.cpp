// mlmap register: scans + odometry poses -> corrected poses (TUM), by scan-to-map ICP and
// a pose graph over overlapping pairs.
#include <cstdint>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "commands.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/tum_poses.hpp"
#include "mlmap/registration/sequence_registration.hpp"
#include "mlmap/registration/trajectory_error.hpp"
#include "register_report.hpp"
#include "number_options.hpp"
#include "progress.hpp"
#include "scan_options.hpp"

namespace mlmap::cli {
namespace {

struct RegisterOptions {
  std::string output;
  ScanOptions input;
  std::string reference;
  std::string report;
  std::string metric = "point-to-plane";
  bool no_refine = false;
  double scan_noise = 0.0;  // m, 0 = measured within each scan
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
  if (options.scan_noise > 0.0) options.config.basin.noise = options.config.basin.source_noise = options.scan_noise;

  registration::SequenceRegistration sequence(options.config);
  std::vector<io::StampedPose> stamped;
  std::vector<Pose> odometry_poses;
  double register_seconds = 0.0;
  std::size_t point_count = 0;
  std::vector<ScanReport> reports;
  Progress progress("register", options.input.scans.size(), !quiet);
  reading.forEach(
      [&](Scan& scan, std::size_t index, std::size_t file) {
        const io::StampedPose guess{odometry.empty() ? static_cast<double>(index) : odometry[index].stamp, scan.pose};
        const auto start = std::chrono::steady_clock::now();
        const registration::VerifiedIcp result = sequence.addScan(scan.points, guess.pose);
        register_seconds += secondsSince(start);
        point_count += scan.size();
        stamped.push_back(guess);
        odometry_poses.push_back(guess.pose);
        // Printed for every scan (stdout): whether its result explains the overlap.
        std::printf("scan %zu: %zu points, %zu/%zu inliers, RMS %.2f cm, %d iterations, %s%s\n", index, scan.size(),
                    result.icp.inliers, result.icp.source_points, 100.0 * result.icp.rms_residual,
                    result.icp.iterations, index == 0 ? "first scan (anchors the map)" : verificationSummary(result).c_str(),
                    sequence.levelledOnFloor(index) ? "; tilt and height from its floor" : "");
        reports.push_back({index, options.input.scans[file], scan.size(), result, sequence.levelledOnFloor(index)});
      },
      [&](std::size_t file) { progress.update(file + 1, std::to_string(point_count) + " points"); });
  progress.finish(std::to_string(point_count) + " points");
  const std::vector<Pose> sequential = sequence.poses();

  double refine_seconds = 0.0;
  registration::RefinementResult refinement;
  if (!options.no_refine) {
    const auto start = std::chrono::steady_clock::now();
    refinement = sequence.refine();
    refine_seconds = secondsSince(start);
    std::printf("refinement: %zu verified pair edges (%zu loop closures, %zu pairs rejected, %zu of them unconstrained), "
                "graph cost %.4g -> %.4g, residual against the other scans RMS %.3f -> %.3f cm (%s) in %.2f s\n",
                refinement.pair_edges, refinement.loop_edges, refinement.rejected_pairs, refinement.unconstrained_pairs,
                refinement.graph.initial_cost, refinement.graph.final_cost, 100.0 * std::sqrt(refinement.residual_before),
                100.0 * std::sqrt(refinement.residual_after),
                refinement.rounds_applied > 0 ? "applied"
                : refinement.pair_edges == 0 ? "kept the scan-to-map poses: no verified pair"
                : refinement.scans_worse > 0 ? "kept the scan-to-map poses: the graph's made a scan worse"
                                             : "kept the scan-to-map poses: the graph's did not clearly lower it",
                refine_seconds);
  }
  if (!options.report.empty()) writeRegisterReport(options.report, reports, options.no_refine ? nullptr : &refinement);
  const std::vector<Pose> poses = sequence.poses();
  for (std::size_t i = 0; i < stamped.size(); ++i) stamped[i].pose = poses[i];
  io::writeTumPoses(options.output, stamped);
  std::printf("%s: %zu scans, %zu points; scan-to-map %.3f s per scan, refinement %.2f s\n",
              options.output.c_str(), stamped.size(), point_count,
              stamped.empty() ? 0.0 : register_seconds / static_cast<double>(stamped.size()), refine_seconds);
  // Scans that match the map but whose residuals spread wider than their own noise predicts:
  // on real scans that is the usual case (calibration and range bias make two scans of one
  // wall disagree by more than either's noise), and nothing here can tell it from a wrong
  // pose. Say what the user can do about it.
  if (options.scan_noise <= 0.0) {
    std::size_t wide = 0;
    std::size_t bent = 0;  // of them: walls within the expected spread, floors and ceilings not
    double widest = 0.0;
    for (const ScanReport& report : reports) {
      const registration::VerifiedIcp& r = report.result;
      if (report.index == 0 || r.verified || r.unconstrained || r.no_overlap || !(r.check.spread > r.check.sigma)) continue;
      ++wide;
      widest = std::max(widest, r.check.spread / r.check.sigma);
      if (registration::onlyLevelDisagrees(r.check, options.config.basin)) ++bent;
    }
    if (wide > 0) {
      std::fflush(stdout);  // after the lines above it, also where both go to one pipe
      std::fprintf(stderr,
                   "register: note: %zu of %zu scans not verified, their residuals up to %.1fx the spread each scan's "
                   "own noise predicts. Scans from a real scanner often disagree by more than their own noise; if the "
                   "map built from %s looks right, --scan-noise M (how far two scans of one surface disagree, "
                   "per scan: 0.012 for PCL's room scans, 0.03 for 3DTK's) lets them verify and the pose graph "
                   "use them\n",
                   wide, reports.size(), widest, options.output.c_str());
      if (bent > 0) {
        std::fprintf(stderr,
                     "register: note: in %zu of them the walls agree within the expected spread and the floors and "
                     "ceilings do not: the scans' level surfaces bend differently (3DTK's floors lie 3-4 cm apart "
                     "near the scanner), which no rigid pose removes\n",
                     bent);
      }
    }
  }
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
      ->default_val(0.05)
      ->check(CLI::PositiveNumber);
  command->add_option("--map-voxel-size", options->config.map_voxel_size,
                      "OcTree resolution of the map's nearest-neighbour grid, m")
      ->default_val(0.1)
      ->check(CLI::PositiveNumber);
  command->add_option("--max-distance", options->config.icp.initial_max_distance,
                      "Smallest first correspondence gate, m (the gate follows the start's error bound: 0.5 m, 10 deg)")
      ->default_val(0.5)
      ->check(CLI::PositiveNumber);
  command->add_flag("--no-refine", options->no_refine, "Scan-to-map only, no pose graph");
  command->add_flag("--no-floor-level", [options](std::int64_t) { options->config.level_from_floor = false; },
                    "Never take a scan's tilt and height from its own floor (a building whose floors are not "
                    "level, e.g. ramps)");
  addNumber(command, "--scan-noise", options->scan_noise,
            "How far each scan's surfaces lie from where another scan sees them at the right pose, m; "
            "verification expects √2 times it between two scans (default: measured within each scan; "
            "real scans disagree by more, PCL's room scans by 1.2 cm each where each one's own noise is 0.45 cm)",
            0.0, Bound::Open);
  command->add_option("--report", options->report,
                      "Write the per-scan figures (start, result, inliers, residual, retries, verified) as JSON");
  addScanOptions(command, options->input,
                 {.poses_help = "Odometry poses (TUM), one per scan in order; without it each scan's own pose",
                  .identity = false});
  command->callback([options, &context] {
    context.run = [options, &context] { return runRegister(*options, context.quiet); };
  });
}

}  // namespace mlmap::cli
