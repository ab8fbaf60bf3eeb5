// Hokuyo SCIP 2.0 (the UTM-30LX of section III): the 6-bit character encoding, line
// checksums, frames, and a client for VV, PP, II, BM, QT, RS, TM, MD/MS and GD/GS.
//
// A frame is an echo of the command, a status line ("00P": two characters and their
// sum), data lines each ending in its sum character, and an empty line. Range data
// come in lines of at most 64 characters + sum; a multi-character value may straddle
// two lines, so the payloads are joined before decoding.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mlmap/driver/transport.hpp"
#include "mlmap/error.hpp"

namespace mlmap::driver {

// The sum character of a line: (sum of its bytes & 0x3F) + 0x30.
char scipChecksum(std::string_view text);
// Decodes 2, 3 or 4 characters ('0'...'o', 6 bits each, most significant first);
// nullopt for a character outside the range or a bad width.
std::optional<std::uint32_t> scipDecode(std::string_view characters);
// `width` characters; value must fit in 6·width bits.
std::string scipEncode(std::uint32_t value, int width);
// Decodes a run of `width`-character values; nullopt on a bad length or character.
std::optional<std::vector<std::uint32_t>> scipDecodeValues(std::string_view characters, int width);

// A line with its sum character appended, then '\n' (what a device sends).
std::string scipLine(std::string_view payload);

// What a status means for `command` (its two-letter symbol is enough), from the tables of
// C-42-03320B: §8.1-8.6 per command, §9 for invalid commands; "" when unknown.
std::string scipStatusMeaning(std::string_view command, std::string_view status);

class ScipError : public Error {
 public:
  enum class Kind { Checksum, Status, Truncated, Timeout, Malformed };
  ScipError(Kind kind, const std::string& message) : Error(message), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

struct ScipFrame {
  std::string echo;                 // the command as echoed
  std::string status;               // two characters, sum checked
  std::vector<std::string> lines;   // data lines with their sum characters, unchecked
};

// The PP parameters; every field comes from the device.
struct ScipParameters {
  std::string model;
  std::uint32_t min_range_mm = 0;  // DMIN
  std::uint32_t max_range_mm = 0;  // DMAX
  std::uint32_t steps_per_revolution = 0;  // ARES
  std::uint32_t first_step = 0;    // AMIN
  std::uint32_t last_step = 0;     // AMAX
  std::uint32_t front_step = 0;    // AFRT
  std::uint32_t scan_rpm = 0;      // SCAN

  double revolutionHz() const { return scan_rpm / 60.0; }  // f of eq. 1
  // rad, beam angle λ of `step` (0 straight ahead, counter-clockwise positive)
  double stepAngle(double step) const;
};

// One scan line of MD/MS/GD/GS.
struct ScipScan {
  std::uint64_t timestamp_ms = 0;  // device clock, unwrapped (t_s of eq. 1)
  std::uint32_t start_step = 0;
  std::uint32_t end_step = 0;
  std::uint32_t cluster = 1;
  std::vector<std::uint32_t> ranges_mm;  // one per cluster; below DMIN = error code
  std::vector<std::uint32_t> intensities;  // ME: one per cluster; empty for MD/MS/GD/GS
};

// Device clock vs host clock, fitted on TM round trips: device_s = offset + rate·host_s.
struct ClockModel {
  double offset_s = 0.0;
  double rate = 1.0;
  double max_residual_s = 0.0;  // s of device time: worst fit residual + half its round trip
  double toDevice(double host_s) const { return offset_s + rate * host_s; }
};

struct ScipCounters {
  std::size_t frames = 0;          // good data frames
  std::size_t dropped_frames = 0;  // frames dropped (bad sum, truncated, unknown status)
  std::size_t skipped_lines = 0;   // lines skipped while resynchronising
};

// Unwraps the 24-bit millisecond device clock.
class TimestampUnwrapper {
 public:
  std::uint64_t unwrap(std::uint32_t raw_ms);

 private:
  std::optional<std::uint64_t> last_;
};

class ScipClient {
 public:
  explicit ScipClient(Transport& transport,
                      std::chrono::milliseconds timeout = std::chrono::milliseconds(1000));

  // Makes sure the sensor speaks SCIP 2.0 and is idle (spec §2, as urg_library does it):
  // QT; a one-character status ("E", SCIP 1.1) is answered with "SCIP2.0", a 0E (time
  // adjust mode) with TM2, and QT is sent again. Returns true when it switched to SCIP 2.0.
  bool connect();
  std::map<std::string, std::string> versionInfo();  // VV
  ScipParameters parameters();                         // PP (also kept for decoding)
  std::map<std::string, std::string> status();         // II
  void laserOn();   // BM
  void stop();      // QT: stops measuring (and continuous scans)
  void reset();     // RS
  // TM0, `samples` × TM1, TM2: round-trip samples (host mid-time, device ms).
  struct TimeSample {
    double host_s;
    double device_s;
    double round_trip_s;
  };
  std::vector<TimeSample> timeSamples(int samples);

  // MD (3-character) or MS (2-character): `count` scans, 0 = until QT; `interval`
  // revolutions skipped after each scan sent (0-9, spec §8.1).
  void startScans(std::uint32_t start_step, std::uint32_t end_step, std::uint32_t cluster,
                  bool three_characters = true, std::uint32_t count = 0, std::uint32_t interval = 0);
  // ME: ranges and intensities (3 characters each), otherwise as MD.
  void startIntensityScans(std::uint32_t start_step, std::uint32_t end_step, std::uint32_t cluster,
                           std::uint32_t count = 0, std::uint32_t interval = 0);
  // The next good scan of the stream; frames that fail their checks are dropped and
  // counted (resynchronising on the next frame) — at most `max_drops` in a row before
  // the last error is rethrown. Throws ScipError(Timeout) when nothing comes in time.
  ScipScan nextScan(int max_drops = 8);
  // GD (3-character) or GS (2-character): one scan.
  ScipScan singleScan(std::uint32_t start_step, std::uint32_t end_step, std::uint32_t cluster,
                      bool three_characters = true);

  const ScipCounters& counters() const { return counters_; }
  const std::optional<ScipParameters>& knownParameters() const { return parameters_; }
  Transport& transport() { return reader_.transport(); }

 private:
  ScipFrame command(const std::string& text, std::initializer_list<std::string_view> ok);
  ScipFrame readFrame(std::string_view expected_echo_prefix);
  std::map<std::string, std::string> keyValues(const ScipFrame& frame, const std::string& command);
  ScipScan decodeScan(const ScipFrame& frame, int width, bool has_timestamp, bool intensities = false);
  void startStream(const std::string& symbol, std::uint32_t start_step, std::uint32_t end_step,
                   std::uint32_t cluster, std::uint32_t count, std::uint32_t interval);

  LineReader reader_;
  std::chrono::milliseconds timeout_;
  std::optional<ScipParameters> parameters_;
  TimestampUnwrapper unwrapper_;
  ScipCounters counters_;
  std::string stream_echo_;  // MD/MS echo prefix while streaming
  int stream_width_ = 3;
  bool stream_intensities_ = false;
  std::uint32_t stream_start_ = 0, stream_end_ = 0, stream_cluster_ = 1;
};

// Least-squares fit of device time against host time (eq. 1's t_s on the host clock).
ClockModel fitClock(const std::vector<ScipClient::TimeSample>& samples);

}  // namespace mlmap::driver
