// mlmap replay: rebuild a scan from a raw log through the same driver code.
#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "mlmap/driver/acquisition.hpp"
#include "mlmap/driver/raw_log.hpp"
#include "mlmap/error.hpp"

namespace mlmap::cli {
namespace {

struct ReplayArguments {
  std::string log;
  std::string output;
};

int runReplay(const ReplayArguments& arguments) {
  const driver::RawLog log = driver::RawLog::load(arguments.log);
  driver::SweepOptions options;
  Pose pose = Pose::Identity();
  driver::sweepFromJson(log.metadata, arguments.log, options, pose);
  driver::ReplayTransport laser_transport(log, 'L', arguments.log + " (laser)");
  driver::ReplayTransport ptu_transport(log, 'P', arguments.log + " (pan-tilt)");
  const auto timeout = std::chrono::milliseconds(options.timeout_ms);
  driver::ScipClient laser(laser_transport, timeout);
  driver::PtuClient ptu(ptu_transport, timeout);
  driver::SweepResult result;
  try {
    result = driver::acquireScan(laser, ptu, options, pose);
  } catch (const Error& error) {
    throw Error(std::string(error.what()) + " — the recorded sweep did not complete, no scan written");
  }
  const auto path = driver::saveScan(arguments.output, driver::nextScanIndex(arguments.output), result.scan);
  std::printf("%s: %zu points from %zu laser scans, %zu frames dropped\n", path.string().c_str(),
              result.scan.size(), result.scan_lines, result.dropped_frames);
  return 0;
}

}  // namespace

void addReplayCommand(CLI::App& app, Context& context) {
  auto arguments = std::make_shared<ReplayArguments>();
  auto* command = app.add_subcommand(
      "replay", "Rebuild the scan of a raw log (mlmap scan --log) bit for bit: writes DIR/scan_NNN.pcd");
  command->add_option("log", arguments->log, "Raw log")->required()->check(CLI::ExistingFile);
  command->add_option("-o,--output", arguments->output, "Output directory")->required();
  command->callback([arguments, &context] { context.run = [arguments] { return runReplay(*arguments); }; });
}

}  // namespace mlmap::cli
