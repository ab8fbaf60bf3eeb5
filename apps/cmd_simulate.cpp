// mlmap simulate: a scene description -> scans, true and odometry poses, ground truth.
#include <chrono>
#include <cstdio>

#include "commands.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"
#include "progress.hpp"

namespace mlmap::cli {
namespace {

struct SimulateArguments {
  std::string scene;
  std::string output;
  bool no_noise = false;
  bool no_drift = false;
  int threads = 0;
};

int runSimulate(const SimulateArguments& arguments, bool quiet) {
  const sim::Scene scene = sim::loadScene(arguments.scene);
  const auto start = std::chrono::steady_clock::now();
  Progress progress("simulate", scene.poses.size(), !quiet);
  sim::SimulateOptions options;
  options.range_noise = !arguments.no_noise;
  options.odometry_drift = !arguments.no_drift;
  options.threads = arguments.threads;
  options.progress = [&progress](std::size_t done, std::size_t) { progress.update(done); };
  const auto scans = sim::simulate(scene, options);
  progress.finish();
  sim::writeSimulation(arguments.output, scene, scans);
  std::size_t points = 0;
  for (const auto& scan : scans) points += scan.scan.size();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %zu scans, %zu points, %zu ground-truth planes -> %s in %.2f s\n",
              arguments.scene.c_str(), scans.size(), points, scene.ground_truth.size(),
              arguments.output.c_str(), seconds);
  return 0;
}

}  // namespace

void addSimulateCommand(CLI::App& app, Context& context) {
  auto arguments = std::make_shared<SimulateArguments>();
  auto* command = app.add_subcommand(
      "simulate",
      "Scan a scene description with a simulated tilting laser: writes scan_NNN.xyz (sensor frame, "
      "x y z label), poses_true.txt, poses_odom.txt, planes_true.json and all_world.xyz");
  command->add_option("scene", arguments->scene, "Scene description (.json), e.g. maps/lab.json")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("-o,--output", arguments->output, "Output directory")->required();
  command->add_flag("--no-noise", arguments->no_noise, "Exact ranges");
  command->add_flag("--no-drift", arguments->no_drift, "Odometry equal to the true poses");
  command->add_option("--threads", arguments->threads, "Threads (default: all cores)")
      ->check(CLI::NonNegativeNumber);
  command->callback([arguments, &context] {
    context.run = [arguments, &context] { return runSimulate(*arguments, context.quiet); };
  });
}

}  // namespace mlmap::cli
