// The driver under random device faults: many sweeps against the emulator, each with
// faults drawn from a fixed seed (bad sums, lost data lines, a laser that stalls or hangs
// up), through the real SCIP and PTU clients and acquireScan. Every sweep must either
// complete with a plausible scan or be refused with mlmap::Error naming a device, within
// a bounded time; under ASan/LSan (build-asan) nothing may leak.
#include <doctest/doctest.h>

#include <chrono>
#include <random>

#include "helpers.hpp"
#include "mlmap/driver/acquisition.hpp"
#include "mlmap/driver/emulator.hpp"
#include "mlmap/sim/scene.hpp"

using namespace mlmap::driver;

namespace {

// A closed 5 × 4 × 3 m room: every ray hits something.
const char* const kRoom = R"({
  "name": "fault room",
  "poses": [{"x": 2.0, "y": 2.0}],
  "surfaces": [
    {"type": "box", "name": "room", "class": "wall", "min": [0, 0, 0], "max": [5, 4, 3]},
    {"type": "box", "name": "crate", "class": "other", "min": [3.5, 2.8, 0], "max": [4.5, 3.8, 0.8]}
  ]
})";

// Each fault on with probability 1/3, at a data frame early enough to hit the sweep.
EmulatorFaults randomFaults(std::mt19937& random) {
  std::uniform_int_distribution<int> frame(0, 24);
  std::bernoulli_distribution on(1.0 / 3.0);
  EmulatorFaults faults;
  faults.bad_checksum_frame = on(random) ? frame(random) : -1;
  faults.dropped_line_frame = on(random) ? frame(random) : -1;
  faults.stall_after_frames = on(random) ? frame(random) : -1;
  faults.disconnect_after_frames = on(random) ? frame(random) : -1;
  return faults;
}

}  // namespace

TEST_CASE("Driver under faults: every sweep completes or is refused cleanly, none hangs") {
  const auto scene = mlmap::sim::parseScene(kRoom, "fault_room.json");
  std::mt19937 random(20261122);
  constexpr int kSweeps = 24;
  int completed = 0, refused = 0;
  for (int sweep = 0; sweep < kSweeps; ++sweep) {
    EmulatorOptions emulator_options;
    emulator_options.time_scale = 4.0;
    emulator_options.seed = static_cast<std::uint64_t>(sweep) + 1;
    emulator_options.base_pose.translation() = Eigen::Vector3d(2.0, 2.0, 0.5);
    emulator_options.laser_over_tcp = sweep % 4 == 3;
    emulator_options.faults = randomFaults(random);
    const EmulatorFaults& faults = emulator_options.faults;
    CAPTURE(sweep);
    CAPTURE(faults.bad_checksum_frame);
    CAPTURE(faults.dropped_line_frame);
    CAPTURE(faults.stall_after_frames);
    CAPTURE(faults.disconnect_after_frames);

    SweepOptions options;
    options.tilt_start_deg = -15.0;
    options.tilt_end_deg = 15.0;
    options.rho_deg = 2.0;
    options.cluster = 8;
    options.time_samples = 3;
    options.timeout_ms = 250;

    const auto start = std::chrono::steady_clock::now();
    try {
      Emulator emulator(scene, emulator_options);
      const auto laser_device =
          emulator_options.laser_over_tcp
              ? openDevice("tcp:127.0.0.1:" + std::to_string(emulator.laserTcpPort()))
              : openDevice(emulator.laserPath());
      const auto ptu_device = openDevice(emulator.ptuPath());
      ScipClient laser(*laser_device, std::chrono::milliseconds(options.timeout_ms));
      PtuClient ptu(*ptu_device, std::chrono::milliseconds(options.timeout_ms));
      const SweepResult result = acquireScan(laser, ptu, options, mlmap::Pose::Identity());
      ++completed;
      // 30° at 80°/s: about 0.6 s of profile, 40 revolutions a second.
      CHECK(result.scan_lines >= 15);
      CHECK(result.scan.size() > result.scan_lines * 100);
      CHECK(result.dropped_frames <= 2);  // at most the two frames spoiled on purpose
      CHECK(result.scan.variances.size() == result.scan.size());
    } catch (const mlmap::Error& error) {
      ++refused;
      const std::string message = error.what();
      CAPTURE(message);
      // Spoiled frames are dropped, not fatal: only a silent or gone laser ends a sweep.
      CHECK((faults.stall_after_frames >= 0 || faults.disconnect_after_frames >= 0));
      CHECK((mlmap::test::contains(message, "/dev/pts/") || mlmap::test::contains(message, "tcp")));
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    CHECK(seconds < 20.0);
  }
  MESSAGE(completed << " sweeps completed, " << refused << " refused, of " << kSweeps);
  CHECK(completed > 0);
  CHECK(refused > 0);
}

TEST_CASE("Driver under faults: each fault alone against a fresh emulator, and none unless asked") {
  const auto scene = mlmap::sim::parseScene(kRoom, "fault_room.json");
  struct Case {
    const char* name;
    EmulatorFaults faults;
    bool completes;
  };
  const std::vector<Case> cases = {
      {"none", {}, true},
      {"bad checksum", {5, -1, -1, -1}, true},
      {"dropped line", {-1, 5, -1, -1}, true},
      {"stall", {-1, -1, 5, -1}, false},
      {"disconnect", {-1, -1, -1, 5}, false},
  };
  for (const Case& fault : cases) {
    CAPTURE(fault.name);
    EmulatorOptions emulator_options;
    emulator_options.time_scale = 4.0;
    emulator_options.base_pose.translation() = Eigen::Vector3d(2.0, 2.0, 0.5);
    emulator_options.faults = fault.faults;
    SweepOptions options;
    options.tilt_start_deg = -10.0;
    options.tilt_end_deg = 10.0;
    options.rho_deg = 2.0;
    options.cluster = 8;
    options.time_samples = 3;
    options.timeout_ms = 250;
    Emulator emulator(scene, emulator_options);
    const auto laser_device = openDevice(emulator.laserPath());
    const auto ptu_device = openDevice(emulator.ptuPath());
    ScipClient laser(*laser_device, std::chrono::milliseconds(options.timeout_ms));
    PtuClient ptu(*ptu_device, std::chrono::milliseconds(options.timeout_ms));
    if (fault.completes) {
      const SweepResult result = acquireScan(laser, ptu, options, mlmap::Pose::Identity());
      CHECK(result.scan_lines >= 8);
      // Exactly the spoiled frame is dropped; with no fault, none.
      CHECK(result.dropped_frames == (fault.faults.bad_checksum_frame >= 0 || fault.faults.dropped_line_frame >= 0 ? 1u : 0u));
    } else {
      const std::string message = mlmap::test::errorOf([&] { acquireScan(laser, ptu, options, mlmap::Pose::Identity()); });
      CHECK(mlmap::test::contains(message, emulator.laserPath()));
    }
  }
}
