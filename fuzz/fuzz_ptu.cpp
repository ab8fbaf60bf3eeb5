// Replies of the pan-tilt unit's ASCII protocol: the first byte picks what the client
// asks (initialise: ED FT I PR PN PX TR TN TX; a position query; a move and an await),
// the rest is what the unit answers ('*' done, '!' refused, asynchronous limits, echo).
#include "fuzz_support.hpp"
#include "mlmap/driver/ptu.hpp"

using mlmap::driver::PtuAxis;
using mlmap::driver::PtuClient;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  mlmap::fuzz::ReplyTransport device(mlmap::fuzz::asText(data + 1, size - 1));
  const std::chrono::milliseconds timeout(0);
  PtuClient ptu(device, timeout);
  mlmap::fuzz::refusedOrRead([&] {
    switch (data[0] % 4) {
      case 0:
        ptu.initialise();
        ptu.setPosition(PtuAxis::Tilt, -100);
        ptu.await(timeout);
        break;
      case 1:
        ptu.position(PtuAxis::Pan);
        ptu.speed(PtuAxis::Tilt);
        ptu.acceleration(PtuAxis::Tilt);
        break;
      case 2:
        ptu.setSpeed(PtuAxis::Tilt, 500);
        ptu.startAwait();
        for (int poll = 0; poll < 3 && !ptu.awaitDone(timeout); ++poll) {
        }
        break;
      case 3:
        ptu.exchange("TP", timeout);
        ptu.baseSpeed(PtuAxis::Pan);
        break;
    }
  });
  return 0;
}
