#include "mlmap/driver/emulator.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "mlmap/driver/scip.hpp"
#include "mlmap/driver/tilt_sync.hpp"
#include "mlmap/error.hpp"

namespace mlmap::driver {
namespace {

int holdSlaveOpen(const std::string& path) {
  // Keeping one slave descriptor open stops the master from seeing a hang-up before the
  // client opens the device (and between two clients).
  return ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
}

}  // namespace

Emulator::Emulator(const sim::Scene& scene, const EmulatorOptions& options)
    : scene_(scene), options_(options), base_pose_(options.base_pose), scip2_(!options.start_in_scip11) {
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

// ---------------------------------------------------------------- pan-tilt unit

std::string Emulator::handlePtu(const std::string& raw_command, bool& deferred_await) {
  auto ok = [this](const std::string& value = "", const std::string& verbose = "") {
    if (value.empty()) return std::string("*\r\n");
    return "* " + (terse_ ? value : verbose + value) + "\r\n";
  };
  auto refused = [](const std::string& why) { return "! " + why + "\r\n"; };
  // Manual §4.2: "Input characters may be in upper or lower case".
  std::string command;
  for (const char c : raw_command) command += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  // §4.4.7 speed control modes: C queries, CI independent (position), CV pure velocity.
  if (command == "C") {
    return ok(control_mode_ == 'V' ? "pure velocity" : "independent", "Speed control mode is ");
  }
  if (command == "CI" || command == "CV") {
    control_mode_ = command[1];
    return ok();
  }
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
      case 'L': return ok(std::to_string(axis.lower), name + " lower speed limit is ");
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
      if (control_mode_ == 'V') {  // §4.4.7: a signed velocity, towards the limit it points at
        if (std::abs(value) > axis.upper) return refused("Illegal speed argument");
        const double at = axisDeg(axis, now);
        const double to = value == 0 ? at : (value > 0 ? axis.max : axis.min) * degrees_per_position;
        if (value != 0) axis.speed = std::abs(value);
        axis.history.push_back({now, at, to, std::max(std::abs(value), 1) * degrees_per_position,
                                std::min(axis.base, std::max(std::abs(value), 1)) * degrees_per_position,
                                axis.accel * degrees_per_position});
        return ok();
      }
      if (value <= 0 || value > axis.upper) return refused("Illegal speed argument");
      axis.speed = value;
      return ok();
    case 'L':  // §4.4.6 lower speed bound
      if (value < 0 || value > axis.upper) return refused("Illegal lower speed limit argument");
      axis.lower = value;
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
      // Input ends the wait at once; only an A (await) has to watch the clock.
      const std::size_t got = ptu_->read(chunk, sizeof(chunk), std::chrono::milliseconds(awaiting ? 1 : 20));
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
