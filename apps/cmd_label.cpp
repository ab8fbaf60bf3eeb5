// mlmap label: every input point, in input order, in the world frame, with the patch
// id of the block that collected it ("x y z id", −1 for none), refined point by point
// against the patches' planes unless --block-labels.
#include <algorithm>
#include <cstdio>
#include <limits>

#include "commands.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/map_file.hpp"
#include "mlmap/io/planes_json.hpp"
#include "mlmap/io/xyz.hpp"
#include "mlmap/planes/point_labels.hpp"
#include "progress.hpp"
#include "scan_options.hpp"

namespace mlmap::cli {
namespace {

struct LabelArguments {
  std::string map;
  std::string output;
  ScanOptions input;
  bool block_labels = false;
  std::string json;  // the planes refitted to their labelled points
};

int runLabel(const LabelArguments& arguments, bool quiet) {
  checkWritable(arguments.output);
  if (!arguments.json.empty()) checkWritable(arguments.json);
  // Every point is written, in input order: the range limits only decide which ones can
  // carry a label (those outside were never mapped).
  ScanOptions input = arguments.input;
  input.range = io::RangeLimits{.min = 0.0, .max = std::numeric_limits<double>::infinity()};
  const ScanReading reading(input, "label", quiet);
  const Map map = io::readMap(arguments.map);
  if (!map.planes()) {
    throw Error(arguments.map + ": the map has no planes; run `mlmap planes " + arguments.map +
                " -o LABELLED.mlmap` and label with that map");
  }
  // The map's frame (MapConfig::origin: a map of a cloud far from the origin): points are
  // labelled there and written back in the scans' coordinates.
  const Eigen::Vector3d& origin = map.config().origin;
  Scan labelled;  // all points, the map's frame
  std::vector<Point> scanner_positions;       // per scan, the map's frame
  std::vector<std::uint32_t> scan_of_point;  // per point
  std::vector<bool> outside_range;           // per point
  std::size_t with_plane = 0;
  Progress progress("label", arguments.input.scans.size(), !quiet);
  reading.forEach(
      [&](Scan& scan, std::size_t index, std::size_t file) {
        // The build refused such a scan: with other limits here every point would be "none".
        io::requireReadingsInRange(scan, arguments.input.range, arguments.input.scans[file], index);
        scan.pose.pretranslate(-origin);
        const std::vector<std::int32_t> labels = labelPoints(map.blocks(), scan);
        const auto scan_index = static_cast<std::uint32_t>(scanner_positions.size());
        scanner_positions.push_back(scan.pose.translation());
        for (std::size_t k = 0; k < scan.size(); ++k) {
          labelled.points.push_back(scan.worldPoint(k));
          labelled.labels.push_back(labels[k]);
          scan_of_point.push_back(scan_index);
          outside_range.push_back(!arguments.input.range.contains(scan.points[k]));
        }
      },
      [&](std::size_t file) { progress.update(file + 1); });
  progress.finish();
  if (!arguments.block_labels)
    refinePointLabels(map.blocks(), map.planes()->planes, labelled.points, labelled.labels,
                      PointLabelRefinement{.noise = labelNoiseCap(*map.planes(), !arguments.input.poses.empty()),
                                           .band = map.planes()->config.epsilon + 0.5 * map.blocks().cellSize(),
                                           .level_gap = map.planes()->config.sparse_gap},
                      // Without a pose file a scan's frame may be the world's, not its
                      // scanner's: then where its beams started is unknown.
                      arguments.input.poses.empty() ? BeamOrigins{} : BeamOrigins{scanner_positions, scan_of_point});
  for (std::size_t k = 0; k < labelled.size(); ++k) {
    std::int32_t& label = labelled.labels[k];
    // Blocks without a plane and points no block collects are both "none" here.
    if (label <= 0 || outside_range[k]) label = -1;
    with_plane += label > 0 ? 1 : 0;
  }
  if (!arguments.json.empty()) {
    const PlaneDetection refitted{refitToPoints(map.planes()->planes, labelled.points, labelled.labels),
                                  map.planes()->stats, map.planes()->config};
    io::writePlanesJson(arguments.json, map, refitted, arguments.map);
  }
  if (!origin.isZero())
    for (Point& point : labelled.points) point += origin;
  io::writeXyz(arguments.output, labelled);
  std::printf("%s: %zu points, %zu on a plane (%.1f %%)\n", arguments.output.c_str(), labelled.size(),
              with_plane, labelled.size() == 0 ? 0.0 : 100.0 * static_cast<double>(with_plane) / static_cast<double>(labelled.size()));
  return 0;
}

}  // namespace

void addLabelCommand(CLI::App& app, Context& context) {
  auto arguments = std::make_shared<LabelArguments>();
  auto* command = app.add_subcommand(
      "label", "Write every scan point in the world frame with the plane id of its block (x y z id, -1 for none)");
  command->add_option("map", arguments->map, "Labelled map (.mlmap, from mlmap planes -o)")->required();
  command->add_option("-o,--output", arguments->output, "Points file to write (.xyz)")->required();
  command->add_option("--json", arguments->json,
                      "Also write the planes JSON with each plane refitted to the points labelled with it "
                      "(normal, offset, centroid and RMS from those points)");
  command->add_flag("--block-labels", arguments->block_labels,
                    "Give every point its block's label as is (default: a point keeps it only when it lies "
                    "on the patch's plane, else takes a neighbouring block's patch it lies on, else none)");
  addScanOptions(command, arguments->input,
                 {.poses_help = "TUM pose file, one pose per scan in order (its positions are the beams' origins, "
                                "which decide between two planes near an edge); give the map's --poses, "
                                "--mount and --up"});
  command->callback([arguments, &context] {
    context.run = [arguments, &context] { return runLabel(*arguments, context.quiet); };
  });
}

}  // namespace mlmap::cli
