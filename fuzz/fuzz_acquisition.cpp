// A whole sweep (driver::acquireScan) against a fuzzed laser and pan-tilt unit at once:
// unlike a replayed raw log, nothing checks what the clients write, so the devices'
// answers alone steer the sweep (PP parameters, PTU resolution and limits, TM times,
// the scan stream). Input: u16 little-endian length of the laser's bytes, the laser's
// bytes, then the pan-tilt unit's.
#include "fuzz_support.hpp"
#include "mlmap/driver/acquisition.hpp"

using namespace mlmap::driver;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const std::string_view input = mlmap::fuzz::asText(data + 2, size - 2);
  const std::size_t laser_bytes = std::min<std::size_t>(data[0] | data[1] << 8, input.size());
  mlmap::fuzz::ReplyTransport laser_device(input.substr(0, laser_bytes));
  mlmap::fuzz::ReplyTransport ptu_device(input.substr(laser_bytes));
  ScipClient laser(laser_device, std::chrono::milliseconds(0));
  PtuClient ptu(ptu_device, std::chrono::milliseconds(0));
  SweepOptions options;  // as the raw-log seed's sweep
  options.tilt_start_deg = -3.0;
  options.tilt_end_deg = 3.0;
  options.rho_deg = 3.0;
  options.cluster = 99;
  options.time_samples = 2;
  mlmap::fuzz::refusedOrRead([&] { acquireScan(laser, ptu, options, mlmap::Pose::Identity()); });
  return 0;
}
