// SCIP 2.0: encoding, checksums, frames and the client, on byte strings as the
// specification shows them and on a pseudo-terminal standing in for the laser.
#include <doctest/doctest.h>

#include <chrono>
#include <string>

#include "helpers.hpp"
#include "mlmap/driver/scip.hpp"
#include "mlmap/driver/transport.hpp"

using namespace mlmap::driver;

namespace {

// A laser on a pty whose answers the test queues before the client asks.
struct FakeLaser {
  PtyPair pty = openPtyPair();
  std::unique_ptr<FdTransport> client = openSerial(pty.slave_path);
  void answer(const std::string& bytes) { pty.master->write(bytes); }
  std::string received() {
    std::string all;
    char buffer[4096];
    while (const auto got = pty.master->read(buffer, sizeof(buffer), std::chrono::milliseconds(20))) {
      all.append(buffer, got);
    }
    return all;
  }
};

std::string frame(const std::string& echo, const std::string& status, const std::string& body = "") {
  return echo + "\n" + scipLine(status) + body + "\n";
}

// A data frame of `values` (3-character encoding), 64 characters per line.
std::string scanFrame(const std::string& echo, std::uint32_t stamp, const std::vector<std::uint32_t>& values,
                      int corrupt_line = -1, int drop_line = -1) {
  std::string data;
  for (const auto value : values) data += scipEncode(value, 3);
  std::string body = scipLine(scipEncode(stamp, 4));
  int line = 0;
  for (std::size_t at = 0; at < data.size(); at += 64, ++line) {
    std::string text = scipLine(data.substr(at, 64));
    if (line == corrupt_line) text[0] = text[0] == '0' ? '1' : '0';
    if (line != drop_line) body += text;
  }
  return frame(echo, "99", body);
}

std::vector<std::uint32_t> ramp(std::size_t count) {
  std::vector<std::uint32_t> values;
  for (std::size_t i = 0; i < count; ++i) values.push_back(static_cast<std::uint32_t>(100 + 37 * i));
  return values;
}

}  // namespace

TEST_CASE("SCIP decoding: the specification's examples") {
  CHECK(scipDecode("CB") == 1234u);       // 2-character example
  CHECK(scipDecode("1Dh") == 5432u);      // 3-character example
  CHECK(scipDecode("m2@0") == 16000000u); // 4-character example
  CHECK(scipEncode(1234, 2) == "CB");
  CHECK(scipEncode(5432, 3) == "1Dh");
  CHECK(scipEncode(16000000, 4) == "m2@0");
  CHECK_FALSE(scipDecode("1"));          // bad width
  CHECK_FALSE(scipDecode("1D\x7f"));     // outside '0'..'o'
  CHECK_FALSE(scipDecode("/00"));
  CHECK_THROWS_AS(scipEncode(4096, 2), mlmap::Error);
  const auto values = scipDecodeValues("CB1Dh", 3);
  CHECK_FALSE(values);  // 5 characters are not whole 3-character values
  REQUIRE(scipDecodeValues("1Dh1Dh", 3));
  CHECK(scipDecodeValues("1Dh1Dh", 3)->size() == 2);
}

TEST_CASE("SCIP checksums: status lines and parameter lines of both firmware kinds") {
  CHECK(scipChecksum("00") == 'P');
  CHECK(scipChecksum("99") == 'b');
  CHECK(scipChecksum("DMIN:23") == '7');    // "DMIN:23;7": ';' left out of the sum
  CHECK(scipChecksum("DMAX:60000") == 'J');
  CHECK(scipChecksum("AMAX:1080") == 'Z');
  CHECK(scipLine("00") == "00P\n");
}

TEST_CASE("SCIP timestamps: the 24-bit clock is unwrapped") {
  TimestampUnwrapper unwrapper;
  CHECK(unwrapper.unwrap(0xFFFFF0) == 0xFFFFF0u);
  CHECK(unwrapper.unwrap(0x000010) == (1ull << 24) + 0x10);
  CHECK(unwrapper.unwrap(0xFFFFFA) == 0xFFFFFAu);  // a slightly older sample: no wrap
  CHECK(unwrapper.unwrap(0x000020) == (1ull << 24) + 0x20);
}

TEST_CASE("SCIP client: PP with and without a semicolon in the sum, VV, II") {
  FakeLaser laser;
  ScipClient client(*laser.client, std::chrono::milliseconds(300));
  // PP as a UTM-30LX answers (';' outside the sum), one line with it inside.
  auto key = [](const std::string& k, const std::string& v, bool with) {
    const std::string payload = k + ":" + v + ";";
    return payload + scipChecksum(with ? payload : payload.substr(0, payload.size() - 1)) + "\n";
  };
  laser.answer(frame("PP", "00",
                     "MODL:UTM-30LX;" + std::string(1, scipChecksum("MODL:UTM-30LX")) + "\nDMIN:23;7\nDMAX:60000;J\n" +
                         key("ARES", "1440", true) + key("AMIN", "0", false) + "AMAX:1080;Z\n" +
                         key("AFRT", "540", false) + key("SCAN", "2400", true)));
  const ScipParameters parameters = client.parameters();
  CHECK(laser.received() == "PP\n");
  CHECK(parameters.model == "UTM-30LX");
  CHECK(parameters.min_range_mm == 23);
  CHECK(parameters.max_range_mm == 60000);
  CHECK(parameters.steps_per_revolution == 1440);
  CHECK(parameters.last_step == 1080);
  CHECK(parameters.front_step == 540);
  CHECK(parameters.revolutionHz() == doctest::Approx(40.0));
  CHECK(parameters.stepAngle(540) == doctest::Approx(0.0));
  CHECK(parameters.stepAngle(900) == doctest::Approx(3.14159265 / 2));

  laser.answer(frame("VV", "00", key("VEND", "Hokuyo", true) + key("PROT", "SCIP 2.0", false)));
  const auto version = client.versionInfo();
  CHECK(version.at("VEND") == "Hokuyo");
  CHECK(version.at("PROT") == "SCIP 2.0");

  laser.answer(frame("II", "00", key("LASR", "OFF", true) + "TIME:5F6F3D;0\n"));  // bad sum
  const auto message = mlmap::test::errorOf([&] { client.status(); });
  CHECK(mlmap::test::contains(message, "II: bad checksum"));
  CHECK(mlmap::test::contains(message, laser.pty.slave_path));
}

TEST_CASE("SCIP client: a parameter set that makes no sense is rejected") {
  FakeLaser laser;
  ScipClient client(*laser.client, std::chrono::milliseconds(300));
  auto key = [](const std::string& k, const std::string& v) {
    const std::string payload = k + ":" + v;
    return payload + ";" + scipChecksum(payload) + "\n";
  };
  laser.answer(frame("PP", "00", key("DMIN", "23") + key("DMAX", "60000") + key("ARES", "0") +
                                     key("AMIN", "0") + key("AMAX", "1080") + key("AFRT", "540") +
                                     key("SCAN", "2400")));
  CHECK(mlmap::test::contains(mlmap::test::errorOf([&] { client.parameters(); }), "inconsistent"));
  laser.answer(frame("PP", "00", key("DMIN", "2x3")));
  CHECK(mlmap::test::contains(mlmap::test::errorOf([&] { client.parameters(); }), "DMIN is not a number"));
}

TEST_CASE("SCIP client: status errors, BM already on, silence") {
  FakeLaser laser;
  ScipClient client(*laser.client, std::chrono::milliseconds(200));
  laser.answer(frame("BM", "02"));  // already on: fine
  client.laserOn();
  laser.answer(frame("RS", "0E"));
  try {
    client.reset();
    FAIL("no error");
  } catch (const ScipError& error) {
    CHECK(error.kind() == ScipError::Kind::Status);
    CHECK(mlmap::test::contains(error.what(), "RS: status '0E'"));
  }
  const auto start = std::chrono::steady_clock::now();
  try {
    client.stop();
    FAIL("no error");
  } catch (const ScipError& error) {
    CHECK(error.kind() == ScipError::Kind::Timeout);
  }
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(1));
}

TEST_CASE("SCIP client: MD stream, values straddling lines, drops and resynchronisation") {
  FakeLaser laser;
  ScipClient client(*laser.client, std::chrono::milliseconds(300));
  const auto values = ramp(1081);  // 3243 characters: values straddle the 64-character lines
  laser.answer(frame("MD0000108001000", "00"));
  laser.answer("garbage left over\n\n");
  laser.answer(scanFrame("MD0000108001000", 0xFFFFF0, values));
  laser.answer(scanFrame("MD0000108001000", 0x000009, values, 5));      // bad sum on line 5
  laser.answer(scanFrame("MD0000108001000", 0x000022, values, -1, 7));  // line 7 lost
  std::string merged = scanFrame("MD0000108001000", 0x00003B, values);
  merged.pop_back();                                                    // end of frame lost
  laser.answer(merged);
  laser.answer(scanFrame("MD0000108001000", 0x000054, values));
  client.startScans(0, 1080, 1, true, 0);
  CHECK(laser.received() == "MD0000108001000\n");
  const ScipScan first = client.nextScan();
  CHECK(first.ranges_mm == values);
  CHECK(first.timestamp_ms == 0xFFFFF0u);
  const ScipScan next = client.nextScan();
  CHECK(next.ranges_mm == values);
  CHECK(next.timestamp_ms == (1ull << 24) + 0x54);
  CHECK(client.counters().dropped_frames == 3);
  CHECK(client.counters().frames == 2);
  CHECK(client.counters().skipped_lines >= 1);
  CHECK_THROWS_AS(client.nextScan(), ScipError);  // nothing more: timeout
}

TEST_CASE("SCIP client: QT during a stream skips a data line that starts with \"QT\"") {
  FakeLaser laser;
  ScipClient client(*laser.client, std::chrono::milliseconds(300));
  // 137472 encodes as "QT0": the frame's first data line starts with QT's echo.
  std::vector<std::uint32_t> values = ramp(1081);
  values[0] = 137472;
  REQUIRE(scipEncode(values[0], 3) == "QT0");
  laser.answer(frame("MD0000108001000", "00"));
  laser.answer(scanFrame("MD0000108001000", 0x000010, values));
  laser.answer(frame("QT", "00"));
  client.startScans(0, 1080, 1, true, 0);
  CHECK_NOTHROW(client.stop());  // was: "QT...: bad status line" (a data line taken for the echo)
  CHECK(laser.received() == "MD0000108001000\nQT\n");
}

TEST_CASE("SCIP client: MS (2-character) with clusters, GD single scan") {
  FakeLaser laser;
  ScipClient client(*laser.client, std::chrono::milliseconds(300));
  std::vector<std::uint32_t> values = {23, 4095, 1000, 7};  // steps 100..106 in clusters of 2
  std::string data;
  for (const auto value : values) data += scipEncode(value, 2);
  laser.answer(frame("MS0100010602001", "00"));
  laser.answer(frame("MS0100010602000", "99", scipLine(scipEncode(77, 4)) + scipLine(data)));
  client.startScans(100, 106, 2, false, 1);
  const ScipScan scan = client.nextScan();
  CHECK(scan.ranges_mm == values);
  CHECK(scan.cluster == 2);
  CHECK(scan.timestamp_ms == 77);

  std::string gd;
  for (const auto value : values) gd += scipEncode(value, 3);
  laser.answer(frame("GD0100010602", "00", scipLine(scipEncode(90, 4)) + scipLine(gd)));
  const ScipScan single = client.singleScan(100, 106, 2, true);
  CHECK(single.ranges_mm == values);
  // Too few values for the requested range: truncated.
  laser.answer(frame("GD0100010602", "00", scipLine(scipEncode(91, 4)) + scipLine(gd.substr(0, 6))));
  try {
    client.singleScan(100, 106, 2, true);
    FAIL("no error");
  } catch (const ScipError& error) {
    CHECK(error.kind() == ScipError::Kind::Truncated);
  }
}

TEST_CASE("SCIP client: TM samples and the clock fit") {
  FakeLaser laser;
  ScipClient client(*laser.client, std::chrono::milliseconds(300));
  laser.answer(frame("TM0", "00"));
  for (std::uint32_t stamp : {1000u, 1001u, 1003u}) {
    laser.answer(frame("TM1", "00", scipLine(scipEncode(stamp, 4))));
  }
  laser.answer(frame("TM2", "00"));
  const auto samples = client.timeSamples(3);
  REQUIRE(samples.size() == 3);
  CHECK(samples[2].device_s == doctest::Approx(1.003));
  CHECK(laser.received() == "TM0\nTM1\nTM1\nTM1\nTM2\n");

  // A device clock 1.5 s ahead that runs 1e-3 fast, over 10 s.
  std::vector<ScipClient::TimeSample> synthetic;
  for (int i = 0; i <= 10; ++i) synthetic.push_back({100.0 + i, 1.5 + (100.0 + i) * 1.001, 0.0});
  const ClockModel model = fitClock(synthetic);
  CHECK(model.rate == doctest::Approx(1.001).epsilon(1e-9));
  CHECK(model.toDevice(105.0) == doctest::Approx(1.5 + 105.0 * 1.001).epsilon(1e-12));
  CHECK(model.max_residual_s < 1e-9);
}
