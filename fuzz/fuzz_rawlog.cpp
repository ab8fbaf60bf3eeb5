// Raw logs through driver::RawLog::load, then what `mlmap replay` does with one: the
// metadata through sweepFromJson and the recorded bytes through the real SCIP and PTU
// clients and acquireScan (a fuzzed log is a fuzzed laser and pan-tilt unit at once).
#include "fuzz_support.hpp"
#include "mlmap/driver/acquisition.hpp"
#include "mlmap/driver/raw_log.hpp"

using namespace mlmap::driver;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = mlmap::fuzz::inputFiles().write("sweep.log", mlmap::fuzz::asText(data, size));
  mlmap::fuzz::refusedOrRead([&] {
    const RawLog log = RawLog::load(path);
    SweepOptions options;
    mlmap::Pose pose = mlmap::Pose::Identity();
    sweepFromJson(log.metadata, path.string(), options, pose);
    ReplayTransport laser_transport(log, 'L', "laser");
    ReplayTransport ptu_transport(log, 'P', "pan-tilt");
    ScipClient laser(laser_transport, std::chrono::milliseconds(options.timeout_ms));
    PtuClient ptu(ptu_transport, std::chrono::milliseconds(options.timeout_ms));
    acquireScan(laser, ptu, options, pose);
  });
  return 0;
}
