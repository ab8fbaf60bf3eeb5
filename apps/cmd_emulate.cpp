// mlmap emulate: a Hokuyo UTM-30LX and a PTU-46-17.5 on pseudo-terminals, scanning a scene.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <thread>

#include "commands.hpp"
#include "mlmap/driver/emulator.hpp"
#include "mlmap/error.hpp"
#include "mlmap/sim/scene.hpp"

namespace mlmap::cli {
namespace {

std::atomic<bool> interrupted{false};
extern "C" void onSignal(int) { interrupted = true; }

struct EmulateArguments {
  std::string scene;
  std::string config;
  std::size_t pose_index = 0;
  double duration_s = 0.0;
  bool tcp = false;
  driver::EmulatorOptions options;
};

int runEmulate(EmulateArguments arguments, bool quiet) {
  const sim::Scene scene = sim::loadScene(arguments.scene);
  if (!arguments.config.empty()) arguments.options.mount = driver::loadMountConfig(arguments.config);
  if (!scene.poses.empty() && arguments.pose_index >= scene.poses.size()) {
    throw Error(arguments.scene + ": no pose " + std::to_string(arguments.pose_index) + " (the scene has " +
                std::to_string(scene.poses.size()) + ")");
  }
  // The scene's sensor pose is the tilt axis; the pan-tilt base sits tilt_axis_height below.
  Pose base = scene.poses.empty() ? Pose::Identity() : scene.sensorPose(arguments.pose_index);
  base.translation().z() -= arguments.options.mount.tilt_axis_height;
  arguments.options.base_pose = base;
  arguments.options.laser_over_tcp = arguments.tcp;
  driver::Emulator emulator(scene, arguments.options);
  if (arguments.tcp) {
    std::printf("laser: tcp:127.0.0.1:%d\n", emulator.laserTcpPort());
  } else {
    std::printf("laser: %s\n", emulator.laserPath().c_str());
  }
  std::printf("ptu: %s\n", emulator.ptuPath().c_str());
  std::fflush(stdout);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  const auto start = std::chrono::steady_clock::now();
  while (!interrupted) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (arguments.duration_s > 0.0 &&
        std::chrono::steady_clock::now() - start > std::chrono::duration<double>(arguments.duration_s)) {
      break;
    }
  }
  emulator.stop();
  if (!quiet) std::fprintf(stderr, "emulate: %zu laser scans sent\n", emulator.framesSent());
  if (emulator.skippedRevolutions() > 0) {
    std::fprintf(stderr, "emulate: %zu revolutions skipped: the scene is too heavy to ray-cast in real "
                 "time; try --time-scale 0.5\n", emulator.skippedRevolutions());
  }
  return 0;
}

}  // namespace

void addEmulateCommand(CLI::App& app, Context& context) {
  auto arguments = std::make_shared<EmulateArguments>();
  auto* command = app.add_subcommand(
      "emulate",
      "Emulate the scanner on pseudo-terminals: a UTM-30LX (SCIP 2.0) and a PTU-46-17.5 that "
      "ray-cast a scene; prints the device paths, runs until Ctrl-C or --duration");
  command->add_option("scene", arguments->scene, "Scene description (.json), e.g. maps/lab.json")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--pose-index", arguments->pose_index, "Scene pose the robot stands at")
      ->capture_default_str();
  command->add_option("--config", arguments->config, "Mount offsets JSON (as for mlmap scan)")
      ->check(CLI::ExistingFile);
  command->add_flag("--tcp", arguments->tcp,
                    "Laser on a loopback TCP port instead of a pty (any number of clients, one after another)");
  command->add_flag("--scip11", arguments->options.start_in_scip11,
                    "Laser starts in SCIP 1.1, like a URG-04LX, until a client sends SCIP2.0");
  command->add_option("--port", arguments->options.tcp_port, "TCP port for --tcp (0: any free)")
      ->capture_default_str();
  command->add_option("--time-scale", arguments->options.time_scale, "Emulated seconds per real second")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--noise", arguments->options.range_sigma, "Range noise σ (m)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command->add_option("--seed", arguments->options.seed, "Noise seed")->capture_default_str();
  command->add_option("--duration", arguments->duration_s, "Stop after this many seconds (0: never)")
      ->capture_default_str();
  command->add_option("--fault-bad-checksum", arguments->options.faults.bad_checksum_frame,
                      "Corrupt a data line's sum in this MD/ME data frame (0-based; off unless given)");
  command->add_option("--fault-drop-line", arguments->options.faults.dropped_line_frame,
                      "Drop a data line of this MD frame");
  command->add_option("--fault-stall", arguments->options.faults.stall_after_frames,
                      "Laser goes silent after this many MD frames");
  command->add_option("--fault-disconnect", arguments->options.faults.disconnect_after_frames,
                      "Laser hangs up after this many MD frames");
  command->callback([arguments, &context] {
    context.run = [arguments, &context] { return runEmulate(*arguments, context.quiet); };
  });
}

}  // namespace mlmap::cli
