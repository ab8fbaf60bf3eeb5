// The emulated UTM-30LX's side of SCIP 2.0 (Hokuyo "Communication Protocol Specification
// for SCIP2.0", C-42-03320B): command parsing with string characters (§7), the status
// codes of each command's table (§8) and of invalid commands (§9), MD/MS/ME streams and
// GD/GS single scans with clusters and scan intervals (§8.1-8.2), and the pacing of the
// data frames. The section numbers in comments are the specification's.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "mlmap/driver/emulator.hpp"
#include "mlmap/driver/scip.hpp"
#include "mlmap/driver/tilt_sync.hpp"
#include "mlmap/error.hpp"

#include <unistd.h>

namespace mlmap::driver {
namespace {

// The UTM-30LX as its PP command describes it (spec §5, table 2).
constexpr std::uint32_t kStepsPerRevolution = 1440, kFirstStep = 0, kLastStep = 1080, kFrontStep = 540;
constexpr std::uint32_t kMinRangeMm = 23, kMaxRangeMm = 30000, kScanRpm = 2400;
constexpr double kRevolutionS = 60.0 / kScanRpm;  // 25 ms
constexpr std::uint32_t kNoEcho = 1;  // error code for "nothing in range" (below DMIN)
// Revolutions (5 s) a late stream may fall behind before the stale ones are skipped (a
// machine too busy to run the emulator); a backlog below that is drained at most one frame
// per half revolution, so it is caught up at twice the scan rate, never in a burst.
constexpr std::uint64_t kMaxBacklog = 200;

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

// "KEY:value;sum": the sum covers the text before ';' (§8.11-8.13: DMIN:20;4, AFRT:384;6,
// TIME:002AA9;f).
std::string keyLine(const std::string& key, const std::string& value) {
  const std::string payload = key + ":" + value;
  return payload + ";" + scipChecksum(payload) + "\n";
}

std::optional<std::uint32_t> decimalField(const std::string& text, std::size_t at, std::size_t width) {
  if (text.size() < at + width) return std::nullopt;
  std::uint32_t value = 0;
  const auto [end, error] = std::from_chars(text.data() + at, text.data() + at + width, value);
  if (error != std::errc() || end != text.data() + at + width) return std::nullopt;
  return value;
}

// §7: up to 16 letters, digits, blanks and '.', '_', '+', '@'.
const char* tagStatus(const std::string& tag) {
  if (tag.size() > 16) return "0G";
  for (const char c : tag) {
    const bool allowed = std::isalnum(static_cast<unsigned char>(c)) || c == ' ' || c == '.' ||
                         c == '_' || c == '+' || c == '@';
    if (!allowed) return "0H";
  }
  return nullptr;
}

// A made-up but monotone return strength for ME: weaker with range, 0 without an echo.
std::uint32_t intensityOf(std::uint32_t range_mm) {
  if (range_mm < kMinRangeMm) return 0;
  return static_cast<std::uint32_t>(std::lround(40000.0 / (1.0 + range_mm * 1e-3)));
}

// The surfaces a frame's beams can reach: a plane through the mid-frame beam origin
// holding the frame's beams to within `spread` (sine of the widest beam's angle to it)
// and `origin_spread` (m) cannot see a rectangle whose corners all lie farther to one
// side than that. Exact (conservative): only rectangles no beam can hit are left out,
// so the frame's ranges are the same as with the whole scene, at a fraction of the cost.
sim::Scene reachableSurfaces(const sim::Scene& scene, const std::vector<Beam>& beams) {
  sim::Scene reachable;
  reachable.cylinders = scene.cylinders;
  if (beams.size() < 3) {
    reachable.surfaces = scene.surfaces;
    return reachable;
  }
  const Beam& middle = beams[beams.size() / 2];
  // The first and last beams span the scan plane (any unit normal keeps the test exact;
  // a good one leaves more out).
  const Eigen::Vector3d across = beams.front().direction.cross(beams.back().direction);
  if (across.norm() < 1e-3) {
    reachable.surfaces = scene.surfaces;
    return reachable;
  }
  const Eigen::Vector3d normal = across.normalized();
  double spread = 0.0, origin_spread = 0.0;
  for (const Beam& beam : beams) {
    spread = std::max(spread, std::abs(normal.dot(beam.direction)));
    origin_spread = std::max(origin_spread, std::abs(normal.dot(beam.origin - middle.origin)) +
                                                (beam.origin - middle.origin).norm() * spread);
  }
  for (const sim::Surface& surface : scene.surfaces) {
    bool above = true, below = true;
    for (const Eigen::Vector3d& corner :
         {surface.corner, Eigen::Vector3d(surface.corner + surface.edge_u),
          Eigen::Vector3d(surface.corner + surface.edge_v),
          Eigen::Vector3d(surface.corner + surface.edge_u + surface.edge_v)}) {
      const Eigen::Vector3d relative = corner - middle.origin;
      const double side = normal.dot(relative);
      const double slack = origin_spread + relative.norm() * spread + 1e-6;
      above = above && side > slack;
      below = below && side < -slack;
    }
    if (!above && !below) reachable.surfaces.push_back(surface);
  }
  return reachable;
}

}  // namespace

std::uint32_t Emulator::deviceMs(double emulated_s) const {
  return static_cast<std::uint32_t>(
      (options_.clock_start_ms + static_cast<std::uint64_t>(std::max(emulated_s, 0.0) * 1000.0)) & 0xFFFFFFu);
}

void Emulator::resetLaserState() {
  laser_on_ = false;
  time_adjust_ = false;
  stream_ = {};
  single_ = {};
  stalled_ = false;
}

// ---------------------------------------------------------------- data frames

std::string Emulator::scanFrame(const std::string& echo, const std::string& status,
                                std::uint64_t revolution, const ScanRequest& request, int frame_index) {
  const double scan_start = static_cast<double>(revolution) * kRevolutionS;
  Axis pan, tilt;
  Pose base_pose;
  {  // a snapshot, so the PTU thread never waits for the ray casting
    std::lock_guard lock(mutex_);
    pan = pan_;
    tilt = tilt_;
    base_pose = base_pose_;
  }
  // Every step is measured at its own time and tilt (§8.1: a cluster reports the
  // smallest of its steps' ranges, errors excluded).
  const double degree = std::numbers::pi / 180.0;
  std::vector<Beam> beams;
  beams.reserve(request.end - request.start + 1);
  for (std::uint32_t step = request.start; step <= request.end; ++step) {
    const double t = stepTime(scan_start, step - kFirstStep, 1.0 / kRevolutionS, kStepsPerRevolution);
    const double lambda = (static_cast<double>(step) - kFrontStep) * 2.0 * std::numbers::pi / kStepsPerRevolution;
    const Beam local = beamAt(options_.mount, axisDeg(pan, t) * degree, axisDeg(tilt, t) * degree, lambda);
    beams.push_back({base_pose * local.origin, base_pose.linear() * local.direction});
  }
  const sim::Scene reachable = reachableSurfaces(scene_, beams);
  const sim::RayCaster caster(reachable);
  std::uint64_t noise = options_.seed * 0x2545f4914f6cdd1dULL + revolution;
  std::vector<std::uint32_t> ranges;
  ranges.reserve(beams.size());
  for (const Beam& beam : beams) {
    const auto hit = caster.cast(beam.origin, beam.direction, kMinRangeMm * 1e-3, kMaxRangeMm * 1e-3);
    std::uint32_t value = kNoEcho;
    if (hit) {
      const double range_mm = (hit->range + options_.range_sigma * gaussian(noise)) * 1000.0;
      value = static_cast<std::uint32_t>(std::clamp(std::lround(range_mm), long{kMinRangeMm},
                                                    long{kMaxRangeMm}));
    }
    ranges.push_back(value);
  }
  const int width = request.encoding == 'S' ? 2 : 3;
  const std::uint32_t limit = width == 2 ? 4095u : 262143u;
  std::string data;
  for (std::size_t first = 0; first < ranges.size(); first += request.cluster) {
    const std::size_t last = std::min(first + request.cluster, ranges.size());
    std::uint32_t value = ranges[first];  // all errors: the first step's error code
    bool measured = false;
    for (std::size_t i = first; i < last; ++i) {
      if (ranges[i] < kMinRangeMm) continue;
      if (!measured || ranges[i] < value) value = ranges[i];
      measured = true;
    }
    data += scipEncode(std::min(value, limit), width);
    if (request.encoding == 'E') data += scipEncode(std::min(intensityOf(value), limit), 3);
  }
  std::string frame = echo + "\n" + scipLine(status) + scipLine(scipEncode(deviceMs(scan_start), 4));
  const EmulatorFaults& faults = options_.faults;
  const bool spoil_sum = frame_index >= 0 && frame_index == faults.bad_checksum_frame;
  const bool drop_line = frame_index >= 0 && frame_index == faults.dropped_line_frame;
  int line = 0;
  for (std::size_t at = 0; at < data.size(); at += 64, ++line) {
    if (drop_line && line == 2) continue;
    std::string text = scipLine(std::string_view(data).substr(at, 64));
    if (spoil_sum && line == 1) text[text.size() - 2] = text[text.size() - 2] == '0' ? '1' : '0';
    frame += text;
  }
  return frame + "\n";
}

// ---------------------------------------------------------------- commands

std::string Emulator::scanRequest(const std::string& echo, const std::string& body, const std::string& tag) {
  auto reply = [&echo](const char* status) { return echo + "\n" + scipLine(status) + "\n"; };
  const bool stream = body[0] == 'M';
  // MD/MS/ME: symbol, start (4), end (4), cluster (2), interval (1), count (2); GD/GS: the first three.
  const std::size_t length = stream ? 15 : 12;
  if (body.size() != length) return reply("0C");  // §9: command with insufficient parameters
  const auto start = decimalField(body, 2, 4), end = decimalField(body, 6, 4), cluster = decimalField(body, 10, 2);
  const auto skip = stream ? decimalField(body, 12, 1) : std::optional<std::uint32_t>(0);
  const auto count = stream ? decimalField(body, 13, 2) : std::optional<std::uint32_t>(0);
  // The status table of §8.1 (MD/MS) and §8.2 (GD/GS), in its order.
  if (!start) return reply("01");
  if (!end) return reply("02");
  if (!cluster) return reply("03");
  if (*end > kLastStep) return reply("04");
  if (*end < *start || *start < kFirstStep) return reply("05");
  if (!skip) return reply("06");
  if (!count) return reply("07");
  if (!stream && !laser_on_) return reply("10");
  ScanRequest request;
  request.active = true;
  request.tag = tag;
  request.encoding = body[1];
  request.start = *start;
  request.end = *end;
  request.cluster = std::max<std::uint32_t>(*cluster, 1);  // §8.1: 0-99, 0 and 1 alike
  request.skip = *skip;
  request.remaining = *count;
  request.endless = *count == 0;
  // Data "taken after the command was received" (§8.1): the next whole revolution.
  request.next_revolution = static_cast<std::uint64_t>(std::floor(emulatedSeconds() / kRevolutionS)) + 1;
  if (stream) {
    request.echo = body.substr(0, 13);
    laser_on_ = true;  // §8.1: the laser switches on by itself
    stream_ = request;
    return reply("00");
  }
  request.echo = echo;
  single_ = request;
  return "";  // the reply is the data frame, when its revolution is over
}

std::string Emulator::handleScip(const std::string& line) {
  if (!scip2_) {  // SCIP 1.1: one status character, no sum (§2; as urg_library reads it)
    if (line == "SCIP2.0") {
      scip2_ = true;
      return line + "\n0\n\n";
    }
    return line + "\nE\n\n";
  }
  const auto semicolon = line.find(';');
  const std::string body = line.substr(0, semicolon);
  const std::string tag = semicolon == std::string::npos ? "" : line.substr(semicolon);
  auto reply = [&line](const std::string& status, const std::string& data = "") {
    return line + "\n" + scipLine(status) + data + "\n";
  };
  if (!tag.empty()) {
    if (const char* status = tagStatus(tag.substr(1))) return reply(status);
  }
  const std::string symbol = body.substr(0, 2);
  // §8.6: in adjust mode the sensor takes no other command. VV and II (which report any
  // state) and RS (which resets it) still answer: the specification leaves them open.
  if (time_adjust_ && symbol != "TM" && body != "VV" && body != "II" && body != "RS") return reply("0E");
  if (symbol == "MD" || symbol == "MS" || symbol == "ME" || symbol == "GD" || symbol == "GS") {
    return scanRequest(line, body, tag);
  }
  if (body == "VV") {
    return reply("00", keyLine("VEND", "Hokuyo Automatic Co.,Ltd.") +
                           keyLine("PROD", "SOKUIKI Sensor TOP-URG UTM-30LX (mlmap emulator)") +
                           keyLine("FIRM", "1.20.00(16/Nov./2009)") + keyLine("PROT", "SCIP 2.0") +
                           keyLine("SERI", "H0000000"));
  }
  if (body == "PP") {
    return reply("00", keyLine("MODL", "UTM-30LX") + keyLine("DMIN", std::to_string(kMinRangeMm)) +
                           keyLine("DMAX", std::to_string(kMaxRangeMm)) +
                           keyLine("ARES", std::to_string(kStepsPerRevolution)) +
                           keyLine("AMIN", std::to_string(kFirstStep)) +
                           keyLine("AMAX", std::to_string(kLastStep)) +
                           keyLine("AFRT", std::to_string(kFrontStep)) +
                           keyLine("SCAN", std::to_string(kScanRpm)));
  }
  if (body == "II") {
    char time_hex[16];
    std::snprintf(time_hex, sizeof(time_hex), "%06X", static_cast<unsigned>(deviceMs(emulatedSeconds())));
    return reply("00", keyLine("MODL", "UTM-30LX") + keyLine("LASR", laser_on_ ? "ON" : "OFF") +
                           keyLine("SCSP", "Standard 2400[rpm]") +
                           keyLine("MESM", time_adjust_ ? "Time adjust mode" : "Measuring by Normal Mode") +
                           keyLine("SBPS", "USB only") + keyLine("TIME", time_hex) +
                           keyLine("STAT", "Stable 000 no error."));
  }
  if (body == "BM") {  // §8.3
    const bool was_on = laser_on_;
    laser_on_ = true;
    return reply(was_on ? "02" : "00");
  }
  if (body == "QT" || body == "RS" || body == "RT") {  // §8.4, §8.5: the laser goes off
    const bool reset = body != "QT";
    stream_.active = single_.active = false;
    laser_on_ = false;
    if (reset) time_adjust_ = false;
    return reply("00");
  }
  if (body == "SCIP2.0") return reply("00");  // already in SCIP 2.0
  if (symbol == "TM") {  // §8.6
    if (body.size() < 3) return reply("0C");
    if (body == "TM0") {
      const bool was = time_adjust_;
      time_adjust_ = true;
      laser_on_ = false;  // "when the sensor is in adjustment mode laser is switched off"
      stream_.active = single_.active = false;
      return reply(was ? "02" : "00");
    }
    if (body == "TM1") {
      if (!time_adjust_) return reply("04");
      return reply("00", scipLine(scipEncode(deviceMs(emulatedSeconds()), 4)));
    }
    if (body == "TM2") {
      const bool was = time_adjust_;
      time_adjust_ = false;
      return reply(was ? "00" : "03");
    }
    return reply("01");
  }
  return reply("0E");  // §9: undefined command
}

// ---------------------------------------------------------------- the laser thread

void Emulator::laserLoop() {
  while (!stop_ && serveLaserClient()) {
  }
}

bool Emulator::serveLaserClient() {
  if (listener_) {
    // Over TCP any number of clients, one after another; each finds the sensor idle
    // (what a closed connection does to the sensor, the specification leaves open).
    laser_.reset();
    while (!stop_ && !laser_) laser_ = listener_->accept(std::chrono::milliseconds(20));
    if (!laser_) return false;
    resetLaserState();
  }
  std::string pending;
  double last_frame_real_s = -1.0;
  try {
    while (!stop_) {
      const double now = emulatedSeconds();
      const bool paced = last_frame_real_s < 0.0 ||
                         now / options_.time_scale - last_frame_real_s >= 0.5 * kRevolutionS / options_.time_scale;
      // Sleep until a command comes in or the next frame is due (emulated seconds), so an
      // idle or streaming laser costs no polling: a command ends the wait at once.
      double next_due = 1e300;
      if (stream_.active) {
        next_due = static_cast<double>(stream_.next_revolution + 1) * kRevolutionS;
        if (!paced) next_due = std::max(next_due, (last_frame_real_s + 0.5 * kRevolutionS / options_.time_scale) *
                                                      options_.time_scale);
      }
      if (single_.active) next_due = std::min(next_due, static_cast<double>(single_.next_revolution + 1) * kRevolutionS);
      const double wait_ms = std::clamp((next_due - now) / options_.time_scale * 1e3, 0.0, 20.0);
      char chunk[512];
      const std::size_t got =
          laser_->read(chunk, sizeof(chunk), std::chrono::milliseconds(static_cast<int>(std::ceil(wait_ms))));
      if (stalled_) continue;
      pending.append(chunk, got);
      if (pending.size() > 4096) pending.clear();  // garbage: drop it
      // §7: a command ends with LF, CR or both.
      for (auto newline = pending.find_first_of("\r\n"); newline != std::string::npos;
           newline = pending.find_first_of("\r\n")) {
        const std::string command = pending.substr(0, newline);
        pending.erase(0, newline + 1);
        if (command.empty()) continue;
        const std::string reply = handleScip(command);
        if (!reply.empty()) laser_->write(reply);
      }
      const double after = emulatedSeconds();
      const auto current = static_cast<std::uint64_t>(std::floor(after / kRevolutionS));
      if (stream_.active && stream_.next_revolution + kMaxBacklog <= current) {
        // Too far behind (a machine too busy to ray-cast in time): skip the stale
        // revolutions, as a device would never have sent them late.
        const std::uint64_t period = stream_.skip + 1;
        const std::uint64_t behind = (current - 1 - stream_.next_revolution) / period;
        skipped_revolutions_ += behind;
        stream_.next_revolution += behind * period;
      }
      // One frame per pass, so commands (QT) are never starved, and at least half a
      // revolution apart, so a backlog never arrives as a burst.
      const double real_s = after / options_.time_scale;
      if (paced && stream_.active && (stream_.next_revolution + 1) * kRevolutionS <= after) {
        std::string echo = stream_.echo;
        if (stream_.endless) {
          echo += "00";
        } else {  // §8.1: the echo carries the scans remaining after this one
          char count[4];
          std::snprintf(count, sizeof(count), "%02u", stream_.remaining - 1);
          echo += count;
        }
        laser_->write(scanFrame(echo + stream_.tag, "99", stream_.next_revolution, stream_, data_frames_));
        last_frame_real_s = real_s;
        stream_.next_revolution += stream_.skip + 1;
        ++data_frames_;
        frames_sent_ = static_cast<std::size_t>(data_frames_);
        if (!stream_.endless && --stream_.remaining == 0) {
          stream_.active = false;
          laser_on_ = false;  // §8.1: switched off after the requested scans
        }
        if (data_frames_ == options_.faults.stall_after_frames) stalled_ = true;
        if (data_frames_ == options_.faults.disconnect_after_frames) {
          laser_.reset();
          if (listener_) return true;  // the next client is served again
          if (laser_slave_hold_ >= 0) ::close(laser_slave_hold_);
          laser_slave_hold_ = -1;
          return false;
        }
      } else if (single_.active && (single_.next_revolution + 1) * kRevolutionS <= after) {
        laser_->write(scanFrame(single_.echo, "00", single_.next_revolution, single_, -1));
        single_.active = false;
      }
    }
  } catch (const Error&) {
    // The client hung up: over TCP wait for the next one; a pty has no next one.
    return listener_ != nullptr;
  }
  return false;
}

}  // namespace mlmap::driver
