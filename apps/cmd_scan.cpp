// mlmap scan: one move-and-stop 3D scan from a Hokuyo (SCIP 2.0) on a pan-tilt unit.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "mlmap/driver/acquisition.hpp"
#include "mlmap/driver/raw_log.hpp"
#include "mlmap/driver/transport.hpp"
#include "mlmap/error.hpp"
#include "progress.hpp"

namespace mlmap::cli {
namespace {

struct ScanArguments {
  std::string laser;
  std::string ptu;
  std::string config;
  std::string output;
  std::string log;
  std::vector<double> pose{0.0, 0.0, 0.0};
  int baud = 115200;
  int ptu_baud = 9600;
  driver::SweepOptions sweep;
};

Pose odometryPose(const std::vector<double>& xy_yaw) {
  Pose pose = Pose::Identity();
  pose.translation() = Eigen::Vector3d(xy_yaw[0], xy_yaw[1], 0.0);
  pose.linear() = Eigen::AngleAxisd(xy_yaw[2] * 3.14159265358979323846 / 180.0, Eigen::Vector3d::UnitZ())
                      .toRotationMatrix();
  return pose;
}

int runScan(ScanArguments arguments, bool quiet) {
  if (!arguments.config.empty()) arguments.sweep.mount = driver::loadMountConfig(arguments.config);
  const Pose pose = odometryPose(arguments.pose);
  auto laser_device = driver::openDevice(arguments.laser, arguments.baud);
  auto ptu_device = driver::openDevice(arguments.ptu, arguments.ptu_baud);
  driver::RawLog log;
  log.metadata = driver::sweepToJson(arguments.sweep, pose);
  std::unique_ptr<driver::Transport> laser_log, ptu_log;
  driver::Transport* laser_transport = laser_device.get();
  driver::Transport* ptu_transport = ptu_device.get();
  if (!arguments.log.empty()) {
    laser_log = std::make_unique<driver::RecordingTransport>(*laser_device, log, 'L');
    ptu_log = std::make_unique<driver::RecordingTransport>(*ptu_device, log, 'P');
    laser_transport = laser_log.get();
    ptu_transport = ptu_log.get();
  }
  const auto timeout = std::chrono::milliseconds(arguments.sweep.timeout_ms);
  driver::ScipClient laser(*laser_transport, timeout);
  driver::PtuClient ptu(*ptu_transport, timeout);
  const double lines_expected =
      std::abs(arguments.sweep.tilt_end_deg - arguments.sweep.tilt_start_deg) / arguments.sweep.rho_deg;
  Progress progress("scan", static_cast<std::size_t>(lines_expected) + 1, !quiet);
  const auto start = std::chrono::steady_clock::now();
  driver::SweepResult result;
  try {
    result = driver::acquireScan(laser, ptu, arguments.sweep, pose,
                                 [&progress](std::size_t lines) { progress.update(lines); });
  } catch (const Error& error) {
    if (!arguments.log.empty()) log.save(arguments.log);
    throw Error(std::string(error.what()) + " — sweep interrupted, no scan written");
  }
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto path = driver::saveScan(arguments.output, driver::nextScanIndex(arguments.output), result.scan);
  if (!arguments.log.empty()) log.save(arguments.log);
  std::printf("%s: %zu points from %zu laser scans in %.2f s (%.1f scans/s, %.0f points/s), "
              "t0 uncertainty %.2f ms, %zu frames dropped, %zu revolutions missed\n",
              path.string().c_str(), result.scan.size(), result.scan_lines, seconds,
              static_cast<double>(result.scan_lines) / seconds,
              static_cast<double>(result.scan.size()) / seconds, result.sync_uncertainty_s * 1e3,
              result.dropped_frames, result.missed_revolutions);
  return 0;
}

}  // namespace

void addScanCommand(CLI::App& app, Context& context) {
  auto arguments = std::make_shared<ScanArguments>();
  auto* command = app.add_subcommand(
      "scan",
      "Take one move-and-stop 3D scan (Hokuyo SCIP 2.0 laser on a Directed Perception pan-tilt): "
      "writes DIR/scan_NNN.pcd (base-frame points, VIEWPOINT = odometry pose) only when the sweep "
      "completes");
  command->add_option("--laser", arguments->laser, "Laser: serial device (/dev/ttyACM0) or tcp:HOST:PORT")
      ->required();
  command->add_option("--ptu", arguments->ptu, "Pan-tilt unit serial device (/dev/ttyUSB0)")->required();
  command->add_option("--config", arguments->config,
                      "Mount offsets JSON: {\"tilt_axis_height\": m, \"laser_offset\": [ux, uy, uz]}")
      ->check(CLI::ExistingFile);
  command->add_option("-o,--output", arguments->output, "Output directory")->required();
  command->add_option("--log", arguments->log, "Record every byte exchanged to this raw log");
  command->add_option("--pose", arguments->pose, "Odometry pose: X Y YAW_DEG")->expected(3);
  command->add_option("--pan", arguments->sweep.pan_deg, "Pan angle α (deg)")->capture_default_str();
  command->add_option("--tilt-start", arguments->sweep.tilt_start_deg, "Tilt start γ_s (deg)")
      ->capture_default_str();
  command->add_option("--tilt-end", arguments->sweep.tilt_end_deg, "Tilt end γ_e (deg)")->capture_default_str();
  command->add_option("--rho", arguments->sweep.rho_deg, "Tilt per laser revolution ρ (deg)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--cluster", arguments->sweep.cluster, "Laser steps per measurement")
      ->check(CLI::Range(1, 99))
      ->capture_default_str();
  command->add_option("--timeout-ms", arguments->sweep.timeout_ms, "Longest device silence accepted (ms)")
      ->check(CLI::Range(1, 60000))
      ->capture_default_str();
  command->add_option("--baud", arguments->baud, "Laser baud rate (serial)")->capture_default_str();
  command->add_option("--ptu-baud", arguments->ptu_baud, "Pan-tilt baud rate")->capture_default_str();
  command->callback([arguments, &context] {
    context.run = [arguments, &context] { return runScan(*arguments, context.quiet); };
  });
}

}  // namespace mlmap::cli
