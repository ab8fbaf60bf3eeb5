// Conformance with Hokuyo's "Communication Protocol Specification for SCIP2.0"
// (C-42-03320B), written from the specification's text, not from the emulator: each test
// names the section it checks. The byte-level tests talk to the emulator raw; the
// end-to-end tests run the driver (ScipClient) against it, so both are held to the text.
#include <doctest/doctest.h>

#include <chrono>
#include <string>

#include "helpers.hpp"
#include "mlmap/driver/emulator.hpp"
#include "mlmap/driver/scip.hpp"
#include "mlmap/driver/transport.hpp"
#include "mlmap/sim/scene.hpp"

using namespace mlmap::driver;

namespace {

// A closed room with a post: every ray hits something, and neighbouring steps differ.
const char* const kRoom = R"({
  "name": "conformance room",
  "poses": [{"x": 2.0, "y": 1.5}],
  "surfaces": [
    {"type": "box", "name": "room", "class": "wall", "min": [0, 0, 0], "max": [6, 4, 3]},
    {"type": "box", "name": "post", "class": "other", "min": [3.0, 1.2, 0], "max": [3.3, 1.5, 2.0]}
  ]
})";

EmulatorOptions exactOptions() {
  EmulatorOptions options;
  options.range_sigma = 0.0;  // the same ranges every revolution while the PTU stands still
  options.base_pose.translation() = Eigen::Vector3d(2.0, 1.5, 1.0);
  return options;
}

// The emulator on a pty, spoken to byte by byte.
struct Raw {
  mlmap::sim::Scene scene = mlmap::sim::parseScene(kRoom, "room.json");
  Emulator emulator;
  std::unique_ptr<Transport> device;
  LineReader reader;
  explicit Raw(const EmulatorOptions& options = exactOptions())
      : emulator(scene, options), device(openDevice(emulator.laserPath())), reader(*device) {}

  // One reply: the lines up to the empty one that ends it (§7: two LFs end a reply).
  std::vector<std::string> reply(std::chrono::milliseconds timeout = std::chrono::milliseconds(1000)) {
    std::vector<std::string> lines;
    for (;;) {
      const auto line = reader.readLine(timeout);
      REQUIRE(line);
      if (line->empty()) return lines;
      lines.push_back(*line);
    }
  }
  std::vector<std::string> ask(const std::string& command) {
    device->write(command + "\n");
    return reply();
  }
  std::string status(const std::string& command) {
    const auto lines = ask(command);
    REQUIRE(lines.size() >= 2);
    CHECK(lines[0] == command);  // §7: the reply starts with the command's echo
    return lines[1].substr(0, 2);
  }
};

bool sumOk(const std::string& line) {
  return line.size() >= 2 && scipChecksum(std::string_view(line).substr(0, line.size() - 1)) == line.back();
}

}  // namespace

TEST_CASE("SCIP §7, §8.11-8.13: checksums as the specification's examples compute them") {
  // The text before ';' is summed: DMIN:20;4 and AFRT:384;6 (PP of §8.12), TIME:002AA9;f.
  CHECK(scipChecksum("DMIN:20") == '4');
  CHECK(scipChecksum("AFRT:384") == '6');
  CHECK(scipChecksum("TIME:002AA9") == 'f');
  CHECK(scipChecksum("00") == 'P');  // "0 0 P" of every table
  CHECK(scipChecksum("99") == 'b');  // "9 9 b" of §8.1
  // Every KEY:value line the emulator sends sums the text before ';', as a real UTM does.
  Raw raw;
  for (const char* command : {"VV", "PP", "II"}) {
    CAPTURE(command);
    const auto lines = raw.ask(command);
    REQUIRE(lines.size() > 3);
    CHECK(lines[1] == "00P");
    for (std::size_t i = 2; i < lines.size(); ++i) {
      const std::string& line = lines[i];
      CAPTURE(line);
      REQUIRE(line.size() >= 3);
      CHECK(line[line.size() - 2] == ';');
      CHECK(scipChecksum(std::string_view(line).substr(0, line.size() - 2)) == line.back());
    }
  }
}

TEST_CASE("SCIP §7, §9: string characters are echoed, too long (0G) or invalid letters (0H) refused") {
  Raw raw;
  const auto vv = raw.ask("VV;probe_1.a+b@c");
  REQUIRE(vv.size() > 2);
  CHECK(vv[0] == "VV;probe_1.a+b@c");
  CHECK(vv[1] == "00P");
  CHECK(raw.status("BM;sixteen  letters") == "00");  // 16, with blanks
  CHECK(raw.status("QT;seventeen letters") == "0G");
  CHECK(raw.status("QT;no#hash") == "0H");
  // A scan's echo keeps the string characters, after the remaining-scan count.
  raw.device->write("MD0100011001001;tag\n");
  const auto ack = raw.reply();
  REQUIRE(ack.size() == 2);
  CHECK(ack[0] == "MD0100011001001;tag");
  CHECK(ack[1] == "00P");
  const auto data = raw.reply();
  REQUIRE(data.size() >= 3);
  CHECK(data[0] == "MD0100011001000;tag");
  CHECK(data[1] == "99b");
}

TEST_CASE("SCIP §8.1: the MD/MS status table, in its order, §9: short and undefined commands") {
  Raw raw;
  CHECK(raw.status("MDx000108001000") == "01");  // starting step non-numeric
  CHECK(raw.status("MD0000x08001000") == "02");  // end step non-numeric
  CHECK(raw.status("MD00001080x1000") == "03");  // cluster count non-numeric
  CHECK(raw.status("MD0000108101000") == "04");  // end step beyond AMAX (1080)
  CHECK(raw.status("MD0100000501000") == "05");  // end step smaller than the start
  CHECK(raw.status("MD000010800100x") == "07");  // number of scans non-numeric
  CHECK(raw.status("MS0000108001x00") == "06");  // scan interval non-numeric
  CHECK(raw.status("MD00001080") == "0C");       // §9: insufficient parameters
  CHECK(raw.status("XY") == "0E");               // §9: undefined command
  // §8.2: GD/GS take the same parameter checks, and 10 while the laser is off.
  CHECK(raw.status("GD0000108101") == "04");
  CHECK(raw.status("GS0100000501") == "05");
  CHECK(raw.status("GD0000108001") == "10");
  // §8.3: BM, then BM again.
  CHECK(raw.status("BM") == "00");
  CHECK(raw.status("BM") == "02");
  CHECK(raw.status("QT") == "00");  // §8.4
}

TEST_CASE("SCIP §8.6: TM modes: 01 invalid code, 02/03 already on/off, 04 time outside adjust mode") {
  Raw raw;
  CHECK(raw.status("TM3") == "01");
  CHECK(raw.status("TM1") == "04");
  CHECK(raw.status("TM2") == "03");
  CHECK(raw.status("BM") == "00");
  CHECK(raw.status("TM0") == "00");
  CHECK(raw.status("TM0") == "02");
  // "laser is switched off and it will not accept any other commands"
  CHECK(raw.status("BM") != "00");
  CHECK(raw.status("MD0000108001000") != "00");
  const auto ii = raw.ask("II");
  CHECK(std::find(ii.begin(), ii.end(), "LASR:OFF;" + std::string(1, scipChecksum("LASR:OFF"))) != ii.end());
  const auto time = raw.ask("TM1");
  REQUIRE(time.size() == 3);
  CHECK(time[1] == "00P");
  CHECK(time[2].size() == 5);
  CHECK(sumOk(time[2]));
  CHECK(raw.status("TM2") == "00");
  CHECK(raw.status("BM") == "00");  // accepted again
}

TEST_CASE("SCIP §8.1: remaining scans in the echo, scan interval honoured, laser off after a finite MD") {
  Raw raw;
  // 3 scans, 2 revolutions skipped after each: stamps 75 ms apart, counts 02, 01, 00.
  raw.device->write("MD0400044001203\n");
  REQUIRE(raw.reply().at(1) == "00P");
  std::vector<std::uint32_t> stamps;
  for (const char* remaining : {"02", "01", "00"}) {
    const auto frame = raw.reply();
    REQUIRE(frame.size() >= 3);
    CHECK(frame[0] == std::string("MD04000440012") + remaining);
    CHECK(frame[1] == "99b");
    REQUIRE(sumOk(frame[2]));
    stamps.push_back(*scipDecode(std::string_view(frame[2]).substr(0, 4)));
  }
  CHECK(stamps[1] - stamps[0] == 75);
  CHECK(stamps[2] - stamps[1] == 75);
  // "switched off after completing the number of scans": GD finds the laser off.
  CHECK(raw.status("GD0400044001") == "10");
}

TEST_CASE("SCIP §8.1: cluster count 00 is 1, a cluster reports its steps' smallest range") {
  Raw raw;
  ScipClient client(*raw.device, std::chrono::milliseconds(1000));
  client.connect();
  client.laserOn();
  // Steps 500-580 sweep across the post's edge: neighbouring ranges differ.
  client.startScans(500, 580, 0, true, 1);
  const ScipScan single = client.nextScan();
  REQUIRE(single.ranges_mm.size() == 81);
  client.startScans(500, 580, 3, true, 1);
  const ScipScan clustered = client.nextScan();
  REQUIRE(clustered.ranges_mm.size() == 27);
  std::size_t not_middle = 0;
  for (std::size_t k = 0; k < clustered.ranges_mm.size(); ++k) {
    std::uint32_t smallest = 0;
    for (std::size_t i = 3 * k; i < std::min<std::size_t>(3 * k + 3, 81); ++i) {
      if (single.ranges_mm[i] < 23) continue;  // errors excluded
      if (smallest == 0 || single.ranges_mm[i] < smallest) smallest = single.ranges_mm[i];
    }
    CHECK(clustered.ranges_mm[k] == smallest);
    if (clustered.ranges_mm[k] != single.ranges_mm[std::min<std::size_t>(3 * k + 1, 80)]) ++not_middle;
  }
  CHECK(not_middle > 0);  // the minimum, not the middle step's range
}

TEST_CASE("SCIP §8.1-8.2 end to end: GD and MD give the same ranges, ME adds intensities") {
  Raw raw;
  ScipClient client(*raw.device, std::chrono::milliseconds(1000));
  client.connect();
  const ScipParameters parameters = client.parameters();
  client.laserOn();
  const ScipScan single = client.singleScan(parameters.first_step, parameters.last_step, 1);
  CHECK(single.ranges_mm.size() == 1081);
  client.startScans(parameters.first_step, parameters.last_step, 1, true, 1);
  const ScipScan streamed = client.nextScan();
  CHECK(streamed.ranges_mm == single.ranges_mm);
  CHECK(streamed.intensities.empty());
  client.startIntensityScans(parameters.first_step, parameters.last_step, 1, 1);
  const ScipScan with_intensity = client.nextScan();
  CHECK(with_intensity.ranges_mm == single.ranges_mm);
  REQUIRE(with_intensity.intensities.size() == single.ranges_mm.size());
  CHECK(*std::min_element(with_intensity.intensities.begin(), with_intensity.intensities.end()) > 0);
  // Stronger returns from nearer surfaces.
  const auto nearest = std::min_element(single.ranges_mm.begin(), single.ranges_mm.end()) - single.ranges_mm.begin();
  const auto farthest = std::max_element(single.ranges_mm.begin(), single.ranges_mm.end()) - single.ranges_mm.begin();
  CHECK(with_intensity.intensities[static_cast<std::size_t>(nearest)] >
        with_intensity.intensities[static_cast<std::size_t>(farthest)]);
  CHECK(client.counters().dropped_frames == 0);  // no fault fires unless asked
}

TEST_CASE("SCIP §2: a sensor that starts in SCIP 1.1 is switched by the driver") {
  EmulatorOptions options = exactOptions();
  options.start_in_scip11 = true;
  Raw raw(options);
  const auto old = raw.ask("VV");
  REQUIRE(old.size() == 2);
  CHECK(old[1] == "E");  // a SCIP 1.1 status: one character, no sum
  ScipClient client(*raw.device, std::chrono::milliseconds(1000));
  try {
    client.versionInfo();
    FAIL("SCIP 1.1 reply taken for SCIP 2.0");
  } catch (const ScipError& error) {
    CHECK(mlmap::test::contains(error.what(), "not in SCIP 2.0"));
  }
  CHECK(client.connect());
  CHECK(client.versionInfo().at("PROT") == "SCIP 2.0");
  CHECK_FALSE(client.connect());  // already in SCIP 2.0: nothing to switch
}

TEST_CASE("SCIP §8.6 via the driver: a sensor left in adjust mode is brought back by connect") {
  Raw raw;
  CHECK(raw.status("TM0") == "00");
  ScipClient client(*raw.device, std::chrono::milliseconds(1000));
  CHECK_FALSE(client.connect());
  client.laserOn();
  CHECK(client.singleScan(540, 550, 1).ranges_mm.size() == 11);
}

TEST_CASE("SCIP §8-9: status meanings from the specification's tables") {
  CHECK(scipStatusMeaning("MD0000108101000", "04") == "end step is out of range");
  CHECK(scipStatusMeaning("GD0100000501", "05") == "end step is smaller than the starting step");
  CHECK(scipStatusMeaning("GD0000108001", "10") == "laser is off");
  CHECK(scipStatusMeaning("TM1", "04") == "adjust mode is off when the time was requested");
  CHECK(scipStatusMeaning("TM3", "01") == "invalid control code");
  CHECK(scipStatusMeaning("BM", "02") == "laser is already on");
  CHECK(scipStatusMeaning("RS", "0E") == "undefined command (2)");
  CHECK(scipStatusMeaning("RS", "0F") == "command with insufficient parameters (2)");
  CHECK(scipStatusMeaning("VV", "0C") == "command with insufficient parameters (1)");
  CHECK(scipStatusMeaning("VV", "0A") == "unable to create transmission data or reply");
  CHECK(scipStatusMeaning("QT", "0G") == "string characters exceed 16 letters");
  CHECK(scipStatusMeaning("MD0000108001000", "55") == "hardware trouble (laser, motor)");
}

TEST_CASE("SCIP over TCP: any number of clients, one after another") {
  EmulatorOptions options = exactOptions();
  options.laser_over_tcp = true;
  const auto scene = mlmap::sim::parseScene(kRoom, "room.json");
  Emulator emulator(scene, options);
  std::vector<std::uint32_t> first;
  for (int client_index = 0; client_index < 3; ++client_index) {
    CAPTURE(client_index);
    const auto device = connectTcp("127.0.0.1", emulator.laserTcpPort());
    ScipClient client(*device, std::chrono::milliseconds(1000));
    client.connect();
    client.laserOn();
    client.startScans(300, 700, 1, true, 0);  // left running: the next client must not see it
    const ScipScan scan = client.nextScan();
    CHECK(scan.ranges_mm.size() == 401);
    if (client_index == 0) first = scan.ranges_mm;
    CHECK(scan.ranges_mm == first);
  }
}
