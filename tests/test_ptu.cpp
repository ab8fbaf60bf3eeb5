// The pan-tilt client on a pseudo-terminal whose answers the test queues.
#include <doctest/doctest.h>

#include <chrono>

#include "helpers.hpp"
#include "mlmap/driver/ptu.hpp"

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
