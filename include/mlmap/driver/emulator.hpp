// An emulator of the scanner of section III, so the real driver code runs end to end
// without hardware: a Hokuyo UTM-30LX speaking SCIP 2.0 and a PTU-46-17.5 speaking the
// Directed Perception protocol, each on a pseudo-terminal (the laser optionally on a
// loopback TCP port instead). The laser ray-casts a scene (sim/scene.hpp) once per
// 25 ms revolution at the tilt the PTU's trapezoidal profile gives at each step's time;
// both devices share one emulated clock that may run faster than real time, so protocol
// timestamps stay consistent at any time scale. Faults can be injected.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "mlmap/driver/kinematics.hpp"
#include "mlmap/driver/transport.hpp"
#include "mlmap/scan.hpp"
#include "mlmap/sim/ray_caster.hpp"
#include "mlmap/sim/scene.hpp"

namespace mlmap::driver {

// Injected faults. Each is off unless set to 0 or more, and counts only MD/MS/ME data
// frames (0-based, over the emulator's life), never GD/GS replies or acknowledgements.
struct EmulatorFaults {
  int bad_checksum_frame = -1;  // data frame whose second data line gets a wrong sum
  int dropped_line_frame = -1;  // data frame that loses its third data line
  int stall_after_frames = -1;  // laser goes silent after this many data frames
  int disconnect_after_frames = -1;  // laser hangs up after this many data frames
};

struct EmulatorOptions {
  double time_scale = 1.0;          // emulated seconds per real second
  double range_sigma = 0.01;        // m, Gaussian range noise
  std::uint64_t seed = 1;
  std::uint32_t clock_start_ms = 0;  // laser clock at start (near 2^24 to test the wrap)
  MountConfig mount;
  Pose base_pose = Pose::Identity();  // pan-tilt base frame -> scene (world) frame
  bool laser_over_tcp = false;       // laser on a loopback TCP port instead of a pty
  int tcp_port = 0;                  // 0: any free port
  // Start in SCIP 1.1 like a URG-04LX fresh from the factory: every command but "SCIP2.0"
  // is answered with SCIP 1.1's one-character status "E" until the host switches (spec §2).
  bool start_in_scip11 = false;
  EmulatorFaults faults;
};

class Emulator {
 public:
  Emulator(const sim::Scene& scene, const EmulatorOptions& options);
  ~Emulator();
  Emulator(const Emulator&) = delete;
  Emulator& operator=(const Emulator&) = delete;

  const std::string& laserPath() const { return laser_path_; }  // pty slave (empty over TCP)
  int laserTcpPort() const;                                       // 0 unless over TCP
  const std::string& ptuPath() const { return ptu_path_; }
  void setBasePose(const Pose& pose);  // for the next revolutions (move-and-stop)
  // s on the laser's (unwrapped) clock when the last tilt move began; nullopt before one.
  std::optional<double> lastTiltMoveStart() const;
  std::size_t framesSent() const { return frames_sent_.load(); }
  // Revolutions not sent because ray casting could not keep up (lower the time scale).
  std::size_t skippedRevolutions() const { return skipped_revolutions_.load(); }
  void stop();

  // Units of the emulated PTU (a PTU-46-17.5).
  static constexpr double kResolutionArcsec = 185.1428;
  static constexpr int kTiltMin = -907, kTiltMax = 604, kPanMin = -3090, kPanMax = 3090;

 private:
  struct Move {
    double start_s;      // emulated
    double from_deg, to_deg, speed, base, accel;
  };
  struct Axis {
    std::vector<Move> history;
    // positions/s, /s²; upper and lower bounds as the manual's §4.4.6 example reports them
    int speed = 1000, base = 100, accel = 2000, upper = 2900, lower = 31;
    int min = 0, max = 0;
    int target = 0;
  };

  double emulatedSeconds() const;
  double axisDeg(const Axis& axis, double t) const;
  // An MD/MS/ME stream or a GD/GS single scan, as requested (emulator_laser.cpp).
  struct ScanRequest {
    bool active = false;
    std::string echo;  // MD/MS/ME: up to the scan interval; GD/GS: the whole command
    std::string tag;   // string characters with their ';' (spec §7), echoed back
    char encoding = 'D';  // 'D' 3-character, 'S' 2-character, 'E' ranges + intensities
    std::uint32_t start = 0, end = 0, cluster = 1, skip = 0, remaining = 0;
    bool endless = true;
    std::uint64_t next_revolution = 0;
  };
  void laserLoop();
  bool serveLaserClient();  // false once the emulator stops or the laser is gone for good
  void ptuLoop();
  void resetLaserState();
  std::string handleScip(const std::string& line);
  std::string scanRequest(const std::string& echo, const std::string& body, const std::string& tag);
  std::string scanFrame(const std::string& echo, const std::string& status, std::uint64_t revolution,
                        const ScanRequest& request, int frame_index);
  std::uint32_t deviceMs(double emulated_s) const;
  std::string handlePtu(const std::string& raw_command, bool& deferred_await);
  bool ptuIdle(double t) const;

  sim::Scene scene_;
  EmulatorOptions options_;
  std::unique_ptr<FdTransport> laser_, ptu_;
  std::unique_ptr<TcpListener> listener_;
  int laser_slave_hold_ = -1, ptu_slave_hold_ = -1;
  std::string laser_path_, ptu_path_;
  std::chrono::steady_clock::time_point start_;
  mutable std::mutex mutex_;  // guards pan_, tilt_, base_pose_ (laser reads, PTU writes)
  Axis pan_, tilt_;
  Pose base_pose_;
  std::atomic<bool> stop_{false};
  std::atomic<std::size_t> frames_sent_{0};
  std::atomic<std::size_t> skipped_revolutions_{0};
  // laser state (laser thread only)
  bool laser_on_ = false, time_adjust_ = false, scip2_ = true;
  ScanRequest stream_, single_;
  int data_frames_ = 0;  // MD/MS/ME data frames sent (the faults count these)
  bool stalled_ = false, gone_ = false;
  // pan-tilt state (PTU thread only)
  bool echo_ptu_ = true, terse_ = false, slaved_ = false;
  char control_mode_ = 'I';  // CI independent (position control) or CV pure velocity
  std::thread laser_thread_, ptu_thread_;
};

}  // namespace mlmap::driver
