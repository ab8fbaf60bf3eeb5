// mlmap_bench pacing [SCENE.json] [--seconds S] [--time-scale X]: how evenly the emulated
// laser delivers MD frames. Streams the whole field of view from `mlmap emulate`'s laser
// (in process, on a pty) for S seconds and prints the host arrival gaps between frames
// (min, median, 99th percentile, max), the device-stamp gaps, the revolutions the emulator
// skipped, and the process CPU time per frame (the emulator's ray casting dominates).
// Run it beside another CPU job to see pacing under load.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "mlmap/driver/emulator.hpp"
#include "mlmap/driver/scip.hpp"
#include "mlmap/driver/transport.hpp"
#include "mlmap/sim/scene.hpp"

namespace mlmap::bench {

int runPacing(int argc, char** argv) {
  std::string scene_path = std::string(MLMAP_SOURCE_DIR) + "/maps/lab.json";
  double seconds = 5.0, time_scale = 1.0;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--seconds") == 0 && k + 1 < argc) {
      seconds = std::stod(argv[++k]);
    } else if (std::strcmp(argv[k], "--time-scale") == 0 && k + 1 < argc) {
      time_scale = std::stod(argv[++k]);
    } else {
      scene_path = argv[k];
    }
  }
  const sim::Scene scene = sim::loadScene(scene_path);
  driver::EmulatorOptions options;
  options.time_scale = time_scale;
  if (!scene.poses.empty()) {
    options.base_pose = scene.sensorPose(0);
    options.base_pose.translation().z() -= options.mount.tilt_axis_height;
  }
  driver::Emulator emulator(scene, options);
  const auto device = driver::openDevice(emulator.laserPath());
  driver::ScipClient laser(*device, std::chrono::milliseconds(2000));
  laser.connect();
  const driver::ScipParameters parameters = laser.parameters();
  laser.laserOn();
  laser.startScans(parameters.first_step, parameters.last_step, 1, true, 0);
  std::vector<double> arrivals;
  std::vector<std::uint64_t> stamps;
  const std::clock_t cpu_start = std::clock();
  const double start = driver::hostSeconds();
  while (driver::hostSeconds() - start < seconds) {
    const driver::ScipScan scan = laser.nextScan();
    arrivals.push_back(device->now());
    stamps.push_back(scan.timestamp_ms);
  }
  const double cpu_s = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  laser.stop();
  std::vector<double> gaps;
  for (std::size_t i = 1; i < arrivals.size(); ++i) gaps.push_back((arrivals[i] - arrivals[i - 1]) * 1e3);
  std::sort(gaps.begin(), gaps.end());
  auto at = [&gaps](double q) { return gaps.empty() ? 0.0 : gaps[static_cast<std::size_t>(q * (gaps.size() - 1))]; };
  std::uint64_t stamp_min = ~0ull, stamp_max = 0;
  for (std::size_t i = 1; i < stamps.size(); ++i) {
    stamp_min = std::min(stamp_min, stamps[i] - stamps[i - 1]);
    stamp_max = std::max(stamp_max, stamps[i] - stamps[i - 1]);
  }
  std::printf("pacing: %s, time scale %.2f, %zu frames in %.1f s\n", scene.name.c_str(), time_scale,
              arrivals.size(), seconds);
  std::printf("  arrival gaps ms: min %.1f  median %.1f  p99 %.1f  max %.1f (one revolution: %.1f ms)\n",
              at(0.0), at(0.5), at(0.99), at(1.0), 25.0 / time_scale);
  std::printf("  device stamp gaps ms: %llu-%llu; revolutions skipped by the emulator: %zu\n",
              static_cast<unsigned long long>(stamp_min), static_cast<unsigned long long>(stamp_max),
              emulator.skippedRevolutions());
  std::printf("  process CPU per frame: %.2f ms\n", cpu_s * 1e3 / std::max<std::size_t>(1, arrivals.size()));
  return 0;
}

}  // namespace mlmap::bench
