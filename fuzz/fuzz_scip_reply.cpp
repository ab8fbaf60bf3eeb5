// SCIP 2.0 replies to one command each: the first byte picks the command, the rest is
// what the laser sends back. Covers frame reassembly (echo search, status line, data
// lines, the empty line) and each command's decoder: VV/II key-value lines, PP
// parameters, BM/QT/RS status, TM time lines, GD/GS scans (3- and 2-character values).
#include "fuzz_support.hpp"
#include "mlmap/driver/scip.hpp"

using mlmap::driver::ScipClient;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  mlmap::fuzz::ReplyTransport device(mlmap::fuzz::asText(data + 1, size - 1));
  ScipClient laser(device, std::chrono::milliseconds(0));
  mlmap::fuzz::refusedOrRead([&] {
    switch (data[0] % 9) {
      case 0: laser.versionInfo(); break;
      case 1: laser.parameters(); break;
      case 2: laser.status(); break;
      case 3: laser.laserOn(); break;
      case 4: laser.stop(); break;
      case 5: laser.reset(); break;
      case 6: laser.timeSamples(3); break;
      case 7: laser.singleScan(0, 43, 1, true); break;  // 44 values: 132 characters, 3 lines
      case 8: laser.singleScan(10, 109, 3, false); break;  // 34 values of 2 characters
    }
  });
  return 0;
}
