// Inputs the fuzz targets (fuzz/, fuzz/README.md) found crashing, hanging or running out
// of memory, each kept with the fix it led to: every one must now be refused cleanly
// with mlmap::Error.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>
#include <string_view>

#include "helpers.hpp"
#include "mlmap/driver/scip.hpp"
#include "mlmap/driver/transport.hpp"

using namespace mlmap::driver;

namespace {

// A device that sends `bytes` and then stays silent, as the fuzz targets drive the clients.
class RecordedDevice : public Transport {
 public:
  explicit RecordedDevice(std::string bytes) : bytes_(std::move(bytes)) {}
  void write(std::string_view) override {}
  std::size_t read(char* buffer, std::size_t capacity, std::chrono::milliseconds) override {
    const std::size_t count = std::min(capacity, bytes_.size() - at_);
    std::memcpy(buffer, bytes_.data() + at_, count);
    at_ += count;
    return count;
  }
  const std::string& name() const override { return name_; }

 private:
  std::string bytes_;
  std::size_t at_ = 0;
  std::string name_ = "recorded laser";
};

}  // namespace

TEST_CASE("fuzz regression scip_stream: a stream of nothing but acknowledgements") {
  // Found by fuzz_scip_stream: nextScan skips status-00 frames (MD's acknowledgement)
  // without counting an error, so after max_drops + 1 of them it rethrew an empty
  // std::optional — a crash. Minimised input (MS, cluster 4):
  const std::string replies =
      "MS0000009904000\n00\n\nMS00000099040M\n00\n\nMS00000099040\n00\n\nMS00000099040\n00\n\n"
      "MS00000099040\n00\n\nMS00000099040\n00\n\nMS00000099040\n00\n\nMS000000990401\n00\n\n"
      "MS00000099040\n00\n\nMS00000099040\n00\n\n\x01";
  RecordedDevice device(replies);
  ScipClient laser(device, std::chrono::milliseconds(0));
  laser.startScans(0, 99, 4, false);
  CHECK_THROWS_WITH_AS(laser.nextScan(), doctest::Contains("frames in a row without scan data"),
                       ScipError);
}
