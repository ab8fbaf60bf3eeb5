// Inputs the fuzz targets (fuzz/, fuzz/README.md) found crashing, hanging or running out
// of memory, each kept with the fix it led to: every one must now be refused cleanly
// with mlmap::Error.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>
#include <string_view>
#include <tuple>

#include "helpers.hpp"
#include "mlmap/driver/acquisition.hpp"
#include "mlmap/driver/kinematics.hpp"
#include "mlmap/driver/scip.hpp"
#include "mlmap/driver/transport.hpp"
#include "mlmap/io/planes_json.hpp"
#include "mlmap/registration/floor_calibration.hpp"
#include "mlmap/sim/scene.hpp"

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
  // std::optional — a crash. The minimised input (MS, cluster 4) had echoes cut to their
  // first 13 characters or ending in stray characters; since an echo must carry the
  // remaining-scan count (a data line that merely starts like one is none), they are
  // written whole here, ten acknowledgements in a row:
  std::string replies;
  for (int k = 0; k < 10; ++k) replies += "MS0000009904000\n00\n\n";
  replies += "\x01";
  RecordedDevice device(replies);
  ScipClient laser(device, std::chrono::milliseconds(0));
  laser.startScans(0, 99, 4, false);
  CHECK_THROWS_WITH_AS(laser.nextScan(), doctest::Contains("frames in a row without scan data"),
                       ScipError);
}

TEST_CASE("fuzz regression rawlog: integers in the sweep metadata that fit no integer") {
  // Run through fuzz_rawlog (a hand-mutated seed; the fuzzer had not got there yet):
  // json's get<int>() of 1e300, like get<unsigned>() of -1e300, is undefined behaviour
  // (UBSan: "1e+300 is outside the range of representable values of type 'int'").
  const std::string good = sweepToJson(SweepOptions{}, mlmap::Pose::Identity());
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const auto at = text.find(from);
    REQUIRE(at != std::string::npos);
    return text.replace(at, from.size(), to);
  };
  SweepOptions options;
  mlmap::Pose pose;
  for (const auto& [from, to, key] :
       {std::tuple{"\"timeout_ms\":1000", "\"timeout_ms\":1e300", "timeout_ms"},
        std::tuple{"\"cluster\":1", "\"cluster\":-1e300", "cluster"},
        std::tuple{"\"cluster\":1", "\"cluster\":-1", "cluster"},
        std::tuple{"\"time_samples\":6", "\"time_samples\":4294967296", "time_samples"},
        std::tuple{"\"time_samples\":6", "\"time_samples\":6.5", "time_samples"}}) {
    CAPTURE(to);
    CHECK_THROWS_WITH_AS(sweepFromJson(replaced(from, to), "sweep.log", options, pose),
                         doctest::Contains((std::string("sweep.log: bad sweep metadata: ") + key).c_str()),
                         mlmap::Error);
  }
  sweepFromJson(good, "sweep.log", options, pose);
  CHECK(options.timeout_ms == 1000);
}

TEST_CASE("fuzz regression planes_json: a number too large for a double") {
  // Found by fuzz_planes_json (a plane's value mutated to 0.9999E804496765137, minimised
  // to "9E850"): nlohmann throws out_of_range, not parse_error, for a number that
  // overflows, and it escaped the reader as a foreign exception. The same held for the
  // mount configuration's reader.
  CHECK_THROWS_WITH_AS(mlmap::io::parsePlanesJson("9E850", "planes.json"),
                       doctest::Contains("planes.json: not valid JSON"), mlmap::Error);
  CHECK_THROWS_WITH_AS(mlmap::io::parsePlanesJson(R"({"schema": 1e999})", "planes.json"),
                       doctest::Contains("planes.json: not valid JSON"), mlmap::Error);
  CHECK_THROWS_WITH_AS(parseMountConfig(R"({"tilt_axis_height": 1e999})", "mount.json"),
                       doctest::Contains("mount.json: bad JSON"), mlmap::Error);
}

TEST_CASE("Regression: a scene or a tilt file with 1e999 or a wrongly typed schema is a clear error") {
  CHECK_THROWS_WITH_AS(mlmap::sim::parseScene(R"({"poses": [{"x": 1e999}], "surfaces": []})", "huge.json"),
                       doctest::Contains("huge.json"), mlmap::Error);
  mlmap::test::TempDir dir;
  for (const char* text : {R"({"schema": 5})", R"({"schema": "mlmap.mount/1", "roll_correction_deg": 1e999})", "[1]"}) {
    mlmap::test::writeText(dir / "tilt.json", text);
    CHECK_THROWS_WITH_AS(mlmap::registration::readMountCorrection(dir / "tilt.json"), doctest::Contains("tilt.json"),
                         mlmap::Error);
  }
}
