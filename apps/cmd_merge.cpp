// mlmap merge: joins the maps of two adjacent spaces into one, with a known
// transform or one found by ICP between the maps.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "commands.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/map_file.hpp"
#include "mlmap/io/transform_file.hpp"
#include "mlmap/map/merge.hpp"
#include "mlmap/registration/map_registration.hpp"
#include "output_check.hpp"

namespace mlmap::cli {
namespace {

struct MergeArguments {
  std::string base;
  std::string other;
  std::string output;
  std::string transform;
  std::string initial;
  std::string write_transform;
  bool register_maps = false;
  bool force = false;
  double max_tilt_deg = 1.0;
};

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

void printTransform(const char* what, const Pose& pose) {
  const Eigen::Vector3d t = pose.translation();
  const Eigen::Vector3d forward = pose.linear() * Eigen::Vector3d::UnitX();
  std::printf("  %s: x %.3f m, y %.3f m, z %.3f m, yaw %.2f°\n", what, t.x(), t.y(), t.z(),
              std::atan2(forward.y(), forward.x()) * 180.0 / std::numbers::pi);
}

int runMerge(const MergeArguments& arguments, bool quiet) {
  const auto start = std::chrono::steady_clock::now();
  checkWritable(arguments.output);
  if (!quiet) std::fprintf(stderr, "merge: reading %s and %s ...\n", arguments.base.c_str(), arguments.other.c_str());
  Map base = io::readMap(arguments.base);
  const Map other = io::readMap(arguments.other);
  Pose other_to_base = Pose::Identity();
  if (!arguments.transform.empty()) other_to_base = io::readTransform(arguments.transform);
  // The maps hold their blocks moved by −origin (MapConfig::origin: a map far from the
  // world's origin). Transforms are given and printed about the base map's origin: the
  // world's for maps near it, and for two maps of a national grid's coordinates a turn
  // about the site rather than about a point 5,000 km away (kilometres of translation). The
  // other map's blocks are moved by the difference of the origins first.
  const Eigen::Vector3d origins_apart = other.config().origin - base.config().origin;
  const auto toMaps = [&](const Pose& given) { return Pose(given * Eigen::Translation3d(origins_apart)); };
  const auto toWorld = [&](const Pose& maps) { return Pose(maps * Eigen::Translation3d(-origins_apart)); };

  std::printf("merge %s + %s\n", arguments.base.c_str(), arguments.other.c_str());
  if (arguments.register_maps) {
    const Pose initial = arguments.initial.empty() ? Pose::Identity() : io::readTransform(arguments.initial);
    if (!quiet) std::fprintf(stderr, "merge: registering the maps (ICP) ...\n");
    const auto icp_start = std::chrono::steady_clock::now();
    registration::MapRegistrationConfig config;
    config.max_tilt_deg = arguments.max_tilt_deg;
    registration::MapRegistration found = registration::registerMaps(base, other, toMaps(initial), config);
    found.other_to_base = toWorld(found.other_to_base);
    printTransform("initial guess", initial);
    printTransform("registered   ", found.other_to_base);
    std::printf("  ICP: %zu of %zu surface samples matched, RMS %.2f cm, overlap %.1f %%, %.2f s%s\n", found.inliers,
                found.samples, 100.0 * found.rms_residual, 100.0 * found.overlap, seconds(icp_start),
                found.reliable ? "" : " — UNRELIABLE");
    std::printf("  verification: %s, %.0f %% of the samples explained, residual spread %.2f cm (surface noise %.2f cm), "
                "%d ICP run%s, %.2f° of tilt levelled\n",
                found.verified ? "verified" : "NOT VERIFIED", 100.0 * found.explained_share,
                100.0 * found.residual_spread, 100.0 * found.noise, found.attempts, found.attempts == 1 ? "" : "s",
                found.tilt_deg);
    if (!found.reliable) {
      if (!arguments.force) {
        throw Error("registration unreliable: " + found.reason +
                    "; give a better --initial guess or a --transform, or --force to merge anyway");
      }
      std::fprintf(stderr, "merge: warning: registration unreliable (%s), merging anyway (--force)\n",
                   found.reason.c_str());
    }
    other_to_base = found.other_to_base;
  } else {
    printTransform(arguments.transform.empty() ? "transform (none given: same frame)" : "transform", other_to_base);
  }

  if (!quiet) std::fprintf(stderr, "merge: fusing blocks and OcTrees ...\n");
  const auto merge_start = std::chrono::steady_clock::now();
  const MergeStats stats = mergeInto(base, other, toMaps(other_to_base), arguments.max_tilt_deg);
  const double merge_seconds = seconds(merge_start);
  io::writeMap(arguments.output, base);
  if (!arguments.write_transform.empty()) {
    double tilt_deg = 0.0;
    // Levelled as the merge levelled it, in the maps' frames.
    io::writeTransform(arguments.write_transform, toWorld(levelledTransform(toMaps(other_to_base), tilt_deg)));
  }
  std::printf("  blocks: %zu + %zu -> %zu (%zu fewer than the sum: overlap fused)\n", stats.base_blocks,
              stats.other_blocks, stats.merged_blocks, stats.base_blocks + stats.other_blocks - stats.merged_blocks);
  std::printf("  cells:  %zu + %zu -> %zu\n", stats.base_cells, stats.other_cells, stats.merged_cells);
  if (base.hasOctree()) std::printf("  OcTree: %zu voxel updates fused\n", stats.fused_voxels);
  if (stats.dropped_tilt_deg > 1e-6) std::printf("  levelled: dropped %.3f° of tilt\n", stats.dropped_tilt_deg);
  std::printf("  merge %.2f s, total %.2f s -> %s (planes cleared: run `mlmap planes` on it)\n", merge_seconds,
              seconds(start), arguments.output.c_str());
  return 0;
}

}  // namespace

void addMergeCommand(CLI::App& app, Context& context) {
  auto arguments = std::make_shared<MergeArguments>();
  auto* command = app.add_subcommand("merge", "Merge the maps of two adjacent spaces (both layers: blocks and OcTree)");
  command->add_option("base", arguments->base, "The map the result's frame comes from (.mlmap)")
      ->required()->check(CLI::ExistingFile);
  command->add_option("other", arguments->other, "The map merged into it (.mlmap)")->required()->check(CLI::ExistingFile);
  command->add_option("-o,--output", arguments->output, "The merged map (.mlmap)")->required();
  auto* transform = command->add_option(
      "--transform", arguments->transform,
      "other -> base transform: 'x y z yaw_deg', 'x y z qx qy qz qw' or a 4x4 matrix (default: same frame); "
      "about the base map's origin (`mlmap info`: the world's unless the map lies far from it)")
      ->check(CLI::ExistingFile);
  auto* register_flag = command->add_flag("--register", arguments->register_maps,
                                          "Find the transform by ICP between the maps' surfaces");
  command->add_option("--initial", arguments->initial, "Initial guess for --register (same formats as --transform)")
      ->check(CLI::ExistingFile)->needs(register_flag);
  command->add_flag("--force", arguments->force, "Merge even when the registration looks unreliable");
  command->add_option("--write-transform", arguments->write_transform, "Write the transform applied (levelled, 4x4 matrix)");
  command->add_option("--max-tilt", arguments->max_tilt_deg,
                      "Largest roll/pitch of the transform that is levelled away, deg (maps are gravity-aligned)")
      ->capture_default_str();
  transform->excludes(register_flag);
  command->callback([arguments, &context] {
    context.run = [arguments, &context] { return runMerge(*arguments, context.quiet); };
  });
}

}  // namespace mlmap::cli
