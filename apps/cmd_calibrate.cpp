// mlmap calibrate: a floor scan -> the roll/pitch (JSON) that level the scanner
// (section VI's self-calibration).
#include <cstdio>

#include "commands.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/scan_file.hpp"
#include "mlmap/registration/floor_calibration.hpp"

namespace mlmap::cli {
namespace {

struct CalibrateOptions {
  std::string scan;
  std::string output;
  registration::FloorCalibrationConfig config;
};

int runCalibrate(const CalibrateOptions& options) {
  const std::vector<Scan> scans = io::readScans(options.scan);
  if (scans.empty()) throw Error(options.scan + ": no scan");
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
  command->add_option("--max-tilt", options->config.max_tilt_deg, "Search the floor within this of level, deg")
      ->default_val(20.0)
      ->check(CLI::Range(0.1, 60.0));
  command->add_option("--inlier-distance", options->config.inlier_distance, "Floor point distance, m")
      ->default_val(0.03)
      ->check(CLI::PositiveNumber);
  command->add_option("scan", options->scan, "Scan of the floor around the robot, sensor frame (first scan of the file)")
      ->required()
      ->check(CLI::ExistingFile);
  command->callback([options, &context] { context.run = [options] { return runCalibrate(*options); }; });
}

}  // namespace mlmap::cli
