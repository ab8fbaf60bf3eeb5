// mlmap calibrate: a floor scan -> the roll/pitch (JSON) that level the scanner
// (section VI's self-calibration).
#include <cstdio>

#include "commands.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/scan_file.hpp"
#include "mlmap/io/scan_input.hpp"
#include "mlmap/registration/floor_calibration.hpp"
#include "number_options.hpp"
#include "output_check.hpp"

namespace mlmap::cli {
namespace {

struct CalibrateOptions {
  std::string scan;
  std::string output;
  registration::FloorCalibrationConfig config;
  io::RangeLimits range;
};

int runCalibrate(const CalibrateOptions& options) {
  checkWritable(options.output);
  std::vector<Scan> scans = io::readScans(options.scan);
  if (scans.empty()) throw Error(options.scan + ": no scan");
  io::requireReadingsInRange(scans.front(), options.range, options.scan, 0);
  io::applyRangeLimits(scans.front(), options.range);
  const registration::FloorCalibration calibration =
      registration::calibrateFromFloor(scans.front().points, options.config);
  registration::writeMountCorrection(options.output, calibration);
  std::printf("%s: roll correction %.3f deg, pitch correction %.3f deg (floor %.3f m below the sensor, "
              "%zu points, RMS %.2f cm)\n",
              options.output.c_str(), calibration.correction.roll_correction_deg,
              calibration.correction.pitch_correction_deg, calibration.floor_distance, calibration.floor_points,
              100.0 * calibration.rms_distance);
  return 0;
}

}  // namespace

void addCalibrateCommand(CLI::App& app, Context& context) {
  auto options = std::make_shared<CalibrateOptions>();
  auto* command = app.add_subcommand(
      "calibrate", "Find the scanner's inclination from a floor scan; write the tilt correction (JSON)");
  command->add_option("-o,--output", options->output, "Mount correction to write (JSON)")->required();
  addNumber(command, "--max-tilt", options->config.max_tilt_deg, "Search the floor within this of level, deg", 0.1,
            Bound::Closed, 60.0)
      ->default_val(20.0);
  addNumber(command, "--inlier-distance", options->config.inlier_distance, "Floor point distance, m", 0.0, Bound::Open)
      ->default_val(0.03);
  addNumber(command, "--min-range", options->range.min, "Drop readings nearer than this to the scanner, m", 0.0,
            Bound::Closed)
      ->capture_default_str();
  addNumber(command, "--max-range", options->range.max, "Drop readings farther than this from the scanner, m", 0.0,
            Bound::Open)
      ->capture_default_str();
  command->add_option("scan", options->scan, "Scan of the floor around the robot, sensor frame (first scan of the file)")
      ->required();
  command->callback([options, &context] { context.run = [options] { return runCalibrate(*options); }; });
}

}  // namespace mlmap::cli
