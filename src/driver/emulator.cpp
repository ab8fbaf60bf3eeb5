#include "mlmap/driver/emulator.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "mlmap/driver/scip.hpp"
#include "mlmap/driver/tilt_sync.hpp"
#include "mlmap/error.hpp"

namespace mlmap::driver {
namespace {

// The UTM-30LX as its PP command describes it.
constexpr std::uint32_t kStepsPerRevolution = 1440, kFirstStep = 0, kLastStep = 1080, kFrontStep = 540;
constexpr std::uint32_t kMinRangeMm = 23, kMaxRangeMm = 30000, kScanRpm = 2400;
constexpr double kRevolutionS = 60.0 / kScanRpm;  // 25 ms
constexpr std::uint32_t kNoEcho = 1;  // error code for "nothing in range" (below DMIN)

// splitmix64 + Box–Muller: the same noise on every platform.
double gaussian(std::uint64_t& state) {
  auto next = [&state] {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  };
  const double u1 = 1.0 - static_cast<double>(next() >> 11) * 0x1.0p-53;
  const double u2 = static_cast<double>(next() >> 11) * 0x1.0p-53;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

std::string keyLine(const std::string& key, const std::string& value, bool semicolon_in_sum) {
  const std::string payload = key + ":" + value + ";";
  const char sum = scipChecksum(semicolon_in_sum ? payload : payload.substr(0, payload.size() - 1));
  return payload + sum + "\n";
}

std::optional<std::uint32_t> decimalField(const std::string& text, std::size_t at, std::size_t width) {
  if (text.size() < at + width) return std::nullopt;
  std::uint32_t value = 0;
  const auto [end, error] = std::from_chars(text.data() + at, text.data() + at + width, value);
  if (error != std::errc() || end != text.data() + at + width) return std::nullopt;
  return value;
}

int holdSlaveOpen(const std::string& path) {
  // Keeping one slave descriptor open stops the master from seeing a hang-up before the
  // client opens the device (and between two clients).
  return ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
}

}  // namespace

Emulator::Emulator(const sim::Scene& scene, const EmulatorOptions& options)
    : scene_(scene), options_(options), caster_(std::make_unique<sim::RayCaster>(scene_)),
      base_pose_(options.base_pose) {
  if (!(options_.time_scale > 0.0)) throw Error("emulator: time scale must be positive");
  pan_.min = kPanMin;
  pan_.max = kPanMax;
  tilt_.min = kTiltMin;
  tilt_.max = kTiltMax;
  if (options_.laser_over_tcp) {
    listener_ = std::make_unique<TcpListener>(options_.tcp_port);
  } else {
    PtyPair laser = openPtyPair();
    laser_ = std::move(laser.master);
    laser_path_ = laser.slave_path;
    laser_slave_hold_ = holdSlaveOpen(laser_path_);
  }
  PtyPair ptu = openPtyPair();
  ptu_ = std::move(ptu.master);
  ptu_path_ = ptu.slave_path;
  ptu_slave_hold_ = holdSlaveOpen(ptu_path_);
  start_ = std::chrono::steady_clock::now();
  laser_thread_ = std::thread([this] { laserLoop(); });
  ptu_thread_ = std::thread([this] { ptuLoop(); });
}

Emulator::~Emulator() { stop(); }

void Emulator::stop() {
  stop_ = true;
  if (laser_thread_.joinable()) laser_thread_.join();
  if (ptu_thread_.joinable()) ptu_thread_.join();
  if (laser_slave_hold_ >= 0) ::close(laser_slave_hold_);
  if (ptu_slave_hold_ >= 0) ::close(ptu_slave_hold_);
  laser_slave_hold_ = ptu_slave_hold_ = -1;
}

int Emulator::laserTcpPort() const { return listener_ ? listener_->port() : 0; }

void Emulator::setBasePose(const Pose& pose) {
  std::lock_guard lock(mutex_);
  base_pose_ = pose;
}

std::optional<double> Emulator::lastTiltMoveStart() const {
  std::lock_guard lock(mutex_);
  if (tilt_.history.empty()) return std::nullopt;
  return tilt_.history.back().start_s + options_.clock_start_ms * 1e-3;
}

double Emulator::emulatedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count() *
         options_.time_scale;
}

double Emulator::axisDeg(const Axis& axis, double t) const {
  for (auto move = axis.history.rbegin(); move != axis.history.rend(); ++move) {
    if (move->start_s <= t) {
      TrapezoidalProfile profile{move->from_deg, move->to_deg, move->speed, move->base, move->accel};
      return profile.angleAt(t - move->start_s);
    }
  }
  return axis.history.empty() ? 0.0 : axis.history.front().from_deg;  // before the first move
}

bool Emulator::ptuIdle(double t) const {
  std::lock_guard lock(mutex_);
  for (const Axis* axis : {&pan_, &tilt_}) {
    if (axis->history.empty()) continue;
    const Move& move = axis->history.back();
    TrapezoidalProfile profile{move.from_deg, move.to_deg, move.speed, move.base, move.accel};
    if (t < move.start_s + profile.duration()) return false;
  }
  return true;
}

// ---------------------------------------------------------------- laser (SCIP 2.0)

std::string Emulator::scanFrame(const std::string& echo, const std::string& status,
                                std::uint64_t revolution, std::uint32_t start, std::uint32_t end,
                                std::uint32_t cluster, int width, int frame_index) {
  const double scan_start = static_cast<double>(revolution) * kRevolutionS;
  std::vector<std::uint32_t> values;
  Axis pan, tilt;
  Pose base_pose;
  {  // a snapshot, so the PTU thread never waits for the ray casting
    std::lock_guard lock(mutex_);
    pan = pan_;
    tilt = tilt_;
    base_pose = base_pose_;
  }
  {
    std::uint64_t noise = options_.seed * 0x2545f4914f6cdd1dULL + revolution;
    const double degree = std::numbers::pi / 180.0;
    for (std::uint32_t first = start; first <= end; first += cluster) {
      // One ray per cluster, at its middle step (the driver times it the same way).
      const double step = first + (std::min(first + cluster - 1, end) - first) / 2.0;
      const double t = stepTime(scan_start, step - kFirstStep, 1.0 / kRevolutionS, kStepsPerRevolution);
      const double tilt_angle = axisDeg(tilt, t) * degree;
      const double pan_angle = axisDeg(pan, t) * degree;
      const double lambda = (step - kFrontStep) * 2.0 * std::numbers::pi / kStepsPerRevolution;
      const Beam beam = beamAt(options_.mount, pan_angle, tilt_angle, lambda);
      const auto hit = caster_->cast(base_pose * beam.origin, base_pose.linear() * beam.direction,
                                     kMinRangeMm * 1e-3, kMaxRangeMm * 1e-3);
      std::uint32_t value = kNoEcho;
      if (hit) {
        const double range_mm = (hit->range + options_.range_sigma * gaussian(noise)) * 1000.0;
        value = static_cast<std::uint32_t>(std::clamp(std::lround(range_mm), long{kMinRangeMm},
                                                      long{kMaxRangeMm}));
      }
      const std::uint32_t limit = width == 2 ? 4095u : 262143u;
      values.push_back(std::min(value, limit));
    }
  }
  std::string data;
  for (const auto value : values) data += scipEncode(value, width);
  const std::uint32_t stamp =
      static_cast<std::uint32_t>((options_.clock_start_ms + revolution * 25) & 0xFFFFFFu);
  std::string frame = echo + "\n" + scipLine(status) + scipLine(scipEncode(stamp, 4));
  int line = 0;
  for (std::size_t at = 0; at < data.size(); at += 64, ++line) {
    if (frame_index == options_.faults.dropped_line_frame && line == 2) continue;
    std::string text = scipLine(std::string_view(data).substr(at, 64));
    if (frame_index == options_.faults.bad_checksum_frame && line == 1) {
      text[text.size() - 2] = text[text.size() - 2] == '0' ? '1' : '0';
    }
    frame += text;
  }
  return frame + "\n";
}

void Emulator::laserLoop() {
  if (listener_) {
    while (!stop_ && !laser_) laser_ = listener_->accept(std::chrono::milliseconds(20));
    if (!laser_) return;
  }
  std::string pending;
  struct Stream {
    bool active = false;
    std::string echo;  // without the count
    std::uint32_t start = 0, end = 0, cluster = 1, remaining = 0;
    bool endless = true;
    int width = 3;
    std::uint64_t next_revolution = 0;
  } stream;
  struct Single {
    bool active = false;
    std::string echo;
    std::uint32_t start = 0, end = 0, cluster = 1;
    int width = 3;
    std::uint64_t revolution = 0;
  } single;
  int frames = 0;
  bool stalled = false;
  bool behind = false;  // scans are due: do not wait for commands
  try {
    while (!stop_) {
      char chunk[512];
      const std::size_t got =
          laser_->read(chunk, sizeof(chunk), std::chrono::milliseconds(behind ? 0 : 1));
      if (stalled) continue;
      pending.append(chunk, got);
      if (pending.size() > 4096) pending.clear();  // garbage: drop it
      for (auto newline = pending.find_first_of("\r\n"); newline != std::string::npos;
           newline = pending.find_first_of("\r\n")) {
        const std::string command = pending.substr(0, newline);
        pending.erase(0, newline + 1);
        if (command.empty()) continue;
        const bool is_md = command.rfind("MD", 0) == 0 || command.rfind("MS", 0) == 0;
        const bool is_gd = command.rfind("GD", 0) == 0 || command.rfind("GS", 0) == 0;
        if ((is_md && command.size() == 15) || (is_gd && command.size() == 12)) {
          const auto start = decimalField(command, 2, 4), end = decimalField(command, 6, 4),
                     cluster = decimalField(command, 10, 2);
          const auto count = is_md ? decimalField(command, 13, 2) : std::optional<std::uint32_t>(0);
          const bool valid = start && end && cluster && count && *start <= *end && *end <= kLastStep &&
                             *start >= kFirstStep && *cluster >= 1;
          if (!valid) {
            laser_->write(command + "\n" + scipLine("0A") + "\n");
            continue;
          }
          const std::uint64_t next =
              static_cast<std::uint64_t>(std::floor(emulatedSeconds() / kRevolutionS)) + 1;
          if (is_md) {
            laser_->write(command + "\n" + scipLine("00") + "\n");
            laser_on_ = true;
            stream = {true, command.substr(0, 13), *start, *end, *cluster, *count, *count == 0,
                      command[1] == 'D' ? 3 : 2, next};
          } else if (!laser_on_) {
            laser_->write(command + "\n" + scipLine("10") + "\n");
          } else {
            single = {true, command, *start, *end, *cluster, command[1] == 'D' ? 3 : 2, next};
          }
          continue;
        }
        if (command == "QT" || command == "RS" || command == "RT") {
          stream.active = false;
          single.active = false;
          laser_on_ = false;
          time_adjust_ = false;
        }
        laser_->write(handleScip(command));
      }
      // Scans whose revolution has ended.
      const double now = emulatedSeconds();
      // One scan per pass, so commands (QT) are never starved. A scene too heavy to cast
      // in real time loses whole revolutions rather than bending the device clock.
      const auto current = static_cast<std::uint64_t>(std::floor(now / kRevolutionS));
      constexpr std::uint64_t kMaxLag = 200;  // revolutions (5 s) caught up on before skipping
      if (stream.active && stream.next_revolution + kMaxLag <= current) {
        skipped_revolutions_ += current - 1 - stream.next_revolution;
        stream.next_revolution = current - 1;
      }
      behind = stream.active && stream.next_revolution + 2 <= current + 1;  // one is due
      if (stream.active &&
          static_cast<double>(stream.next_revolution + 1) * kRevolutionS <= now) {
        const std::string count = stream.endless ? "00" : (stream.remaining < 10 ? "0" : "") +
                                                              std::to_string(stream.remaining - 1);
        laser_->write(scanFrame(stream.echo + count, "99", stream.next_revolution, stream.start,
                                stream.end, stream.cluster, stream.width, frames));
        ++stream.next_revolution;
        ++frames;
        frames_sent_ = static_cast<std::size_t>(frames);
        if (!stream.endless && --stream.remaining == 0) stream.active = false;
        if (frames == options_.faults.stall_after_frames) stalled = true;
        if (frames == options_.faults.disconnect_after_frames) {
          laser_.reset();
          if (laser_slave_hold_ >= 0) ::close(laser_slave_hold_);
          laser_slave_hold_ = -1;
          return;
        }
      }
      if (single.active && static_cast<double>(single.revolution + 1) * kRevolutionS <= now) {
        laser_->write(scanFrame(single.echo, "00", single.revolution, single.start, single.end,
                                single.cluster, single.width, -1));
        single.active = false;
      }
    }
  } catch (const Error&) {
    // The client hung up: nothing more to emulate on this device.
  }
}

std::string Emulator::handleScip(const std::string& command) {
  auto frame = [&command](const std::string& status, const std::string& body = "") {
    return command + "\n" + scipLine(status) + body + "\n";
  };
  if (command == "VV") {
    return frame("00", keyLine("VEND", "Hokuyo Automatic Co.,Ltd.", true) +
                           keyLine("PROD", "SOKUIKI Sensor TOP-URG UTM-30LX (mlmap emulator)", true) +
                           keyLine("FIRM", "1.20.00(16/Nov./2009)", true) +
                           keyLine("PROT", "SCIP 2.0", true) + keyLine("SERI", "H0000000", true));
  }
  if (command == "PP") {  // this firmware leaves the ';' out of the sum
    return frame("00", keyLine("MODL", "UTM-30LX", false) +
                           keyLine("DMIN", std::to_string(kMinRangeMm), false) +
                           keyLine("DMAX", std::to_string(kMaxRangeMm), false) +
                           keyLine("ARES", std::to_string(kStepsPerRevolution), false) +
                           keyLine("AMIN", std::to_string(kFirstStep), false) +
                           keyLine("AMAX", std::to_string(kLastStep), false) +
                           keyLine("AFRT", std::to_string(kFrontStep), false) +
                           keyLine("SCAN", std::to_string(kScanRpm), false));
  }
  if (command == "II") {
    char time_hex[16];
    std::snprintf(time_hex, sizeof(time_hex), "%06X",
                  static_cast<unsigned>((options_.clock_start_ms +
                                         static_cast<std::uint64_t>(emulatedSeconds() * 1000.0)) &
                                        0xFFFFFFu));
    return frame("00", keyLine("MODL", "UTM-30LX", true) +
                           keyLine("LASR", laser_on_ ? "ON" : "OFF", true) +
                           keyLine("SCSP", "Standard 2400[rpm]", true) +
                           keyLine("MESM", "Measuring by Normal Mode", true) +
                           keyLine("SBPS", "USB only", true) + keyLine("TIME", time_hex, true) +
                           keyLine("STAT", "Stable 000 no error.", true));
  }
  if (command == "BM") {
    const bool was_on = laser_on_;
    laser_on_ = true;
    return frame(was_on ? "02" : "00");
  }
  if (command == "QT" || command == "RS" || command == "RT" || command == "SCIP2.0") {
    return frame("00");
  }
  if (command == "TM0") {
    const bool was = time_adjust_;
    time_adjust_ = true;
    return frame(was ? "02" : "00");
  }
  if (command == "TM1") {
    if (!time_adjust_) return frame("01");
    const auto ms = options_.clock_start_ms + static_cast<std::uint64_t>(emulatedSeconds() * 1000.0);
    return frame("00", scipLine(scipEncode(static_cast<std::uint32_t>(ms & 0xFFFFFFu), 4)));
  }
  if (command == "TM2") {
    const bool was = time_adjust_;
    time_adjust_ = false;
    return frame(was ? "00" : "03");
  }
  return frame("0E");
}

// ---------------------------------------------------------------- pan-tilt unit

std::string Emulator::handlePtu(const std::string& command, bool& deferred_await) {
  auto ok = [this](const std::string& value = "", const std::string& verbose = "") {
    if (value.empty()) return std::string("*\r\n");
    return "* " + (terse_ ? value : verbose + value) + "\r\n";
  };
  auto refused = [](const std::string& why) { return "! " + why + "\r\n"; };
  if (command == "ED") { echo_ptu_ = false; return ok(); }
  if (command == "EE") { echo_ptu_ = true; return ok(); }
  if (command == "FT") { terse_ = true; return ok(); }
  if (command == "FV") { terse_ = false; return ok(); }
  if (command == "I") { slaved_ = false; return ok(); }
  if (command == "S") { slaved_ = true; return ok(); }
  if (command == "A") {
    deferred_await = true;
    return "";
  }
  if (command.size() < 2 || (command[0] != 'P' && command[0] != 'T')) return refused("Illegal command");
  Axis& axis = command[0] == 'P' ? pan_ : tilt_;
  const std::string name = command[0] == 'P' ? "Pan" : "Tilt";
  const char what = command[1];
  const std::string argument = command.substr(2);
  const double degrees_per_position = kResolutionArcsec / 3600.0;
  if (what == 'R' && argument.empty()) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.4f", kResolutionArcsec);
    return ok(std::string(text) + (terse_ ? "" : " seconds arc per position"));
  }
  if (what == 'N' && argument.empty()) return ok(std::to_string(axis.min), "Minimum " + name + " position is ");
  if (what == 'X' && argument.empty()) return ok(std::to_string(axis.max), "Maximum " + name + " position is ");
  std::lock_guard lock(mutex_);
  const double now = emulatedSeconds();
  if (argument.empty()) {
    switch (what) {
      case 'P': return ok(std::to_string(std::lround(axisDeg(axis, now) / degrees_per_position)),
                          "Current " + name + " position is ");
      case 'S': return ok(std::to_string(axis.speed), "Target " + name + " speed is ");
      case 'B': return ok(std::to_string(axis.base), name + " base speed is ");
      case 'A': return ok(std::to_string(axis.accel), name + " acceleration is ");
      case 'U': return ok(std::to_string(axis.upper), name + " upper speed limit is ");
      default: return refused("Illegal command");
    }
  }
  int value = 0;
  const auto [end, error] = std::from_chars(argument.data(), argument.data() + argument.size(), value);
  if (error != std::errc() || end != argument.data() + argument.size()) return refused("Illegal argument");
  switch (what) {
    case 'P': {
      if (value < axis.min || value > axis.max) {
        return refused((value < axis.min ? "Minimum " : "Maximum ") + std::string("allowable ") + name +
                       " position exceeded");
      }
      axis.target = value;
      if (!slaved_) {
        axis.history.push_back({now, axisDeg(axis, now), value * degrees_per_position,
                                axis.speed * degrees_per_position, axis.base * degrees_per_position,
                                axis.accel * degrees_per_position});
      }
      return ok();
    }
    case 'S':
      if (value <= 0 || value > axis.upper) return refused("Illegal speed argument");
      axis.speed = value;
      return ok();
    case 'B':
      if (value < 0 || value > axis.upper) return refused("Illegal base speed argument");
      axis.base = value;
      return ok();
    case 'A':
      if (value <= 0) return refused("Illegal acceleration argument");
      axis.accel = value;
      return ok();
    default: return refused("Illegal command");
  }
}

void Emulator::ptuLoop() {
  std::string pending;
  bool awaiting = false;
  try {
    while (!stop_) {
      char chunk[256];
      const std::size_t got = ptu_->read(chunk, sizeof(chunk), std::chrono::milliseconds(1));
      if (echo_ptu_ && got > 0) ptu_->write(std::string_view(chunk, got));
      pending.append(chunk, got);
      if (pending.size() > 1024) pending.clear();
      if (awaiting) {
        if (!ptuIdle(emulatedSeconds())) continue;
        awaiting = false;
        ptu_->write("*\r\n");
      }
      for (auto delimiter = pending.find_first_of(" \r\n"); !awaiting && delimiter != std::string::npos;
           delimiter = pending.find_first_of(" \r\n")) {
        const std::string command = pending.substr(0, delimiter);
        pending.erase(0, delimiter + 1);
        if (command.empty()) continue;
        bool deferred = false;
        const std::string reply = handlePtu(command, deferred);
        if (deferred) {
          if (slaved_) {  // slaved moves start now
            std::lock_guard lock(mutex_);
            const double now = emulatedSeconds();
            const double degrees_per_position = kResolutionArcsec / 3600.0;
            for (Axis* axis : {&pan_, &tilt_}) {
              const double at = axisDeg(*axis, now);
              if (std::abs(at - axis->target * degrees_per_position) > 1e-9) {
                axis->history.push_back({now, at, axis->target * degrees_per_position,
                                         axis->speed * degrees_per_position,
                                         axis->base * degrees_per_position,
                                         axis->accel * degrees_per_position});
              }
            }
          }
          awaiting = true;
        } else {
          ptu_->write(reply);
        }
      }
    }
  } catch (const Error&) {
  }
}

}  // namespace mlmap::driver
