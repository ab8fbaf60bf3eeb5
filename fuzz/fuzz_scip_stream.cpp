// A SCIP 2.0 MD/MS scan stream: the acknowledgement and then data frames, read with
// nextScan until the stream ends. Covers resynchronisation after lost frame ends,
// dropped frames (bad sums, short data), timestamps unwrapping, line-straddling values.
// The first byte picks MD (3 characters) or MS (2) and the cluster size.
#include "fuzz_support.hpp"
#include "mlmap/driver/scip.hpp"

using mlmap::driver::ScipClient;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  mlmap::fuzz::ReplyTransport device(mlmap::fuzz::asText(data + 1, size - 1));
  ScipClient laser(device, std::chrono::milliseconds(0));
  const bool three_characters = (data[0] & 1) == 0;
  const std::uint32_t cluster = (data[0] & 2) ? 4 : 1;
  mlmap::fuzz::refusedOrRead([&] {
    laser.startScans(0, 99, cluster, three_characters);
    for (int scan = 0; scan < 64; ++scan) laser.nextScan();
  });
  return 0;
}
