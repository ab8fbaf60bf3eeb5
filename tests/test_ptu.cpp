// The pan-tilt client on a pseudo-terminal whose answers the test queues.
#include <doctest/doctest.h>

#include <chrono>
#include <thread>

#include "helpers.hpp"
#include "mlmap/driver/emulator.hpp"
#include "mlmap/driver/ptu.hpp"
#include "mlmap/sim/scene.hpp"

using namespace mlmap::driver;

namespace {
struct FakePtu {
  PtyPair pty = openPtyPair();
  std::unique_ptr<FdTransport> client = openSerial(pty.slave_path, 9600);
  void answer(const std::string& bytes) { pty.master->write(bytes); }
  std::string received() {
    std::string all;
    char buffer[1024];
    while (const auto got = pty.master->read(buffer, sizeof(buffer), std::chrono::milliseconds(20))) {
      all.append(buffer, got);
    }
    return all;
  }
};
}  // namespace

TEST_CASE("PTU client: initialise with echo and verbose replies, resolution from PR/TR") {
  FakePtu device;
  PtuClient ptu(*device.client, std::chrono::milliseconds(300));
  // Echo still on for the first reply, verbose text as a unit fresh from power-up says it.
  device.answer("ED *\r\n*\r\n*\r\n");
  device.answer("* 185.1428 seconds arc per position\r\n* Minimum Pan position is -3090\r\n"
                "* Maximum Pan position is 3090\r\n");
  device.answer("* 46.2857\r\n* -3600\r\n* 2000\r\n");
  ptu.initialise();
  CHECK(device.received() == "ED FT I PR PN PX TR TN TX ");
  CHECK(ptu.axis(PtuAxis::Pan).resolution_arcsec == doctest::Approx(185.1428));
  CHECK(ptu.axis(PtuAxis::Pan).min_position == -3090);
  CHECK(ptu.axis(PtuAxis::Tilt).degreesPerPosition() == doctest::Approx(46.2857 / 3600.0));
  CHECK(ptu.axis(PtuAxis::Tilt).max_position == 2000);

  device.answer("*\r\n* 1234\r\n");
  ptu.setSpeed(PtuAxis::Tilt, 1234);
  CHECK(ptu.speed(PtuAxis::Tilt) == 1234);
  CHECK(device.received() == "TS1234 TS ");
  // Outside the queried limits: refused before anything is sent.
  CHECK_THROWS_AS(ptu.setPosition(PtuAxis::Tilt, 2001), PtuError);
  CHECK(device.received().empty());
}

TEST_CASE("PTU client: '!' replies, asynchronous limit errors, silence, await") {
  FakePtu device;
  PtuClient ptu(*device.client, std::chrono::milliseconds(200));
  device.answer("! Illegal speed argument\r\n");
  try {
    ptu.setSpeed(PtuAxis::Pan, 99999);
    FAIL("no error");
  } catch (const PtuError& error) {
    CHECK(error.kind() == PtuError::Kind::Refused);
    CHECK(mlmap::test::contains(error.what(), "PS99999: refused: Illegal speed argument"));
  }
  device.answer("!T\r\n");
  try {
    ptu.position(PtuAxis::Tilt);
    FAIL("no error");
  } catch (const PtuError& error) {
    CHECK(error.kind() == PtuError::Kind::Limit);
    CHECK(mlmap::test::contains(error.what(), "tilt limit hit"));
  }
  device.answer("* twelve\r\n");
  CHECK_THROWS_AS(ptu.position(PtuAxis::Pan), PtuError);
  try {
    ptu.position(PtuAxis::Pan);
    FAIL("no error");
  } catch (const PtuError& error) {
    CHECK(error.kind() == PtuError::Kind::Timeout);
    CHECK(mlmap::test::contains(error.what(), device.pty.slave_path));
  }
  device.received();
  ptu.startAwait();
  CHECK_FALSE(ptu.awaitDone(std::chrono::milliseconds(0)));
  device.answer("*\r\n");
  CHECK(ptu.awaitDone(std::chrono::milliseconds(200)));
  CHECK(ptu.awaitDone(std::chrono::milliseconds(0)));  // nothing pending
  CHECK(ptu.lastReplied() >= ptu.lastSent());
}

namespace {
const char* const kEmptyRoom = R"({
  "name": "ptu room",
  "poses": [{"x": 0.0, "y": 0.0}],
  "surfaces": [{"type": "box", "name": "room", "class": "wall", "min": [-3, -3, -1], "max": [3, 3, 2]}]
})";
}  // namespace

TEST_CASE("PTU emulator, manual §4.2: lower-case commands as the ptu46 driver sends them") {
  const auto scene = mlmap::sim::parseScene(kEmptyRoom, "room.json");
  Emulator emulator(scene, EmulatorOptions{});
  const auto device = openDevice(emulator.ptuPath(), 9600);
  PtuClient ptu(*device, std::chrono::milliseconds(500));
  // "Input characters may be in upper or lower case": ft ed ci tr, as ptu46 starts.
  CHECK(ptu.exchange("ft", std::chrono::milliseconds(500)).empty());
  CHECK(ptu.exchange("ed", std::chrono::milliseconds(500)).empty());
  CHECK(ptu.exchange("ci", std::chrono::milliseconds(500)).empty());
  CHECK(ptu.exchange("tr", std::chrono::milliseconds(500)) == "185.1428");
  CHECK(ptu.exchange("Pn", std::chrono::milliseconds(500)) == "-3090");
  ptu.initialise();  // the upper-case path still works after
  CHECK(ptu.axis(PtuAxis::Tilt).max_position == Emulator::kTiltMax);
}

TEST_CASE("PTU emulator, manual §4.4.6-4.4.7: PL/TL speed bounds, C/CI/CV control modes") {
  const auto scene = mlmap::sim::parseScene(kEmptyRoom, "room.json");
  Emulator emulator(scene, EmulatorOptions{});
  const auto device = openDevice(emulator.ptuPath(), 9600);
  PtuClient ptu(*device, std::chrono::milliseconds(500));
  ptu.initialise();
  const auto timeout = std::chrono::milliseconds(500);
  // §4.4.6's example: "PL * Minimum Pan speed is 31 positions/sec", then "PL40 *".
  CHECK(ptu.exchange("PL", timeout) == "31");
  CHECK(ptu.exchange("PL40", timeout).empty());
  CHECK(ptu.exchange("PL", timeout) == "40");
  CHECK(ptu.exchange("tl", timeout) == "31");
  CHECK_THROWS_AS(ptu.exchange("TL-5", timeout), PtuError);
  // §4.4.7: independent by default; in pure velocity mode a signed PS moves the axis.
  CHECK(ptu.exchange("C", timeout) == "independent");
  CHECK(ptu.exchange("CV", timeout).empty());
  CHECK(ptu.exchange("c", timeout) == "pure velocity");
  CHECK(ptu.exchange("PS-1000", timeout).empty());
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const int moved = ptu.position(PtuAxis::Pan);
  CHECK(moved < -60);  // from 100 positions/s up at 2000/s²: 120 positions in 0.3 s
  CHECK(ptu.exchange("PS0", timeout).empty());
  const int stopped = ptu.position(PtuAxis::Pan);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  CHECK(std::abs(ptu.position(PtuAxis::Pan) - stopped) <= 1);
  CHECK(ptu.exchange("CI", timeout).empty());
  CHECK_THROWS_AS(ptu.exchange("PS-1000", timeout), PtuError);  // independent: a magnitude
}
