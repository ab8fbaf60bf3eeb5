// The SCIP 2.0 client: frames read and checked line by line against a deadline, the
// commands, the scans decoded (the encoding itself is in scip_codec.cpp).
#include "mlmap/driver/scip.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace mlmap::driver {
namespace {

constexpr std::size_t kMaxDataPayload = 64;  // characters per data line before the sum
constexpr std::size_t kMaxFrameLines = 4096;
constexpr std::size_t kMaxSkippedLines = 20000;  // while looking for an echo (a flushed stream)

bool sumMatches(std::string_view line) {
  return line.size() >= 2 && scipChecksum(line.substr(0, line.size() - 1)) == line.back();
}

std::string quoted(std::string_view text) {
  std::string out = "'";
  for (const char c : text.substr(0, 40)) {
    if (c >= 0x20 && c < 0x7f) {
      out += c;
    } else {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", static_cast<unsigned char>(c));
      out += hex;
    }
  }
  return out + (text.size() > 40 ? "...'" : "'");
}

std::string decimal(std::uint32_t value, int width) {
  std::string text = std::to_string(value);
  if (static_cast<int>(text.size()) > width) throw Error("SCIP: value " + text + " too wide");
  return std::string(static_cast<std::size_t>(width) - text.size(), '0') + text;
}

std::string statusMeaning(std::string_view command, std::string_view status) {
  const std::string meaning = scipStatusMeaning(command, status);
  return meaning.empty() ? "" : " (" + meaning + ")";
}

}  // namespace

ScipClient::ScipClient(Transport& transport, std::chrono::milliseconds timeout)
    : reader_(transport), timeout_(timeout) {}

ScipFrame ScipClient::readFrame(std::string_view expected_echo_prefix) {
  const auto deadline = std::chrono::steady_clock::now() + timeout_;
  const std::string& device = reader_.transport().name();
  auto nextLine = [&](const char* waiting_for) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    auto line = reader_.readLine(std::max(left, std::chrono::milliseconds(0)));
    if (!line) {
      throw ScipError(ScipError::Kind::Timeout,
                      device + ": " + std::string(expected_echo_prefix.substr(0, 2)) +
                          ": no answer within " + std::to_string(timeout_.count()) +
                          " ms (waiting for " + waiting_for + ")");
    }
    if (!line->empty() && line->back() == '\r') line->pop_back();
    return *line;
  };
  // The awaited echo is the command itself, or the command and its string characters
  // (';' on, §2); a stream's echo (MD/MS/ME and its parameters, 13 characters) also
  // carries the remaining-scan count, two digits. A bare prefix test took a data line of a
  // stream that QT interrupts for QT's echo: a line of encoded ranges starts with any two
  // of the 64 characters, "QT" once in 4096 lines (seen under load in the raw-log test).
  const bool stream = !stream_echo_.empty() && expected_echo_prefix == stream_echo_;
  const auto isEcho = [&](std::string_view line) {
    if (line.substr(0, expected_echo_prefix.size()) != expected_echo_prefix) return false;
    std::string_view rest = line.substr(expected_echo_prefix.size());
    if (stream && rest.size() >= 2 && std::isdigit(static_cast<unsigned char>(rest[0])) != 0 &&
        std::isdigit(static_cast<unsigned char>(rest[1])) != 0) {
      rest.remove_prefix(2);
    }
    return rest.empty() || rest.front() == ';';
  };
  std::string echo;
  std::size_t skipped = 0;
  for (;;) {
    echo = nextLine("the echo");
    if (isEcho(echo)) break;
    if (++skipped > kMaxSkippedLines) {
      throw ScipError(ScipError::Kind::Malformed,
                      device + ": no " + std::string(expected_echo_prefix) + " echo in " +
                          std::to_string(kMaxSkippedLines) + " lines");
    }
    ++counters_.skipped_lines;
  }
  for (;;) {
    ScipFrame frame;
    frame.echo = echo;
    bool restarted = false;
    for (;;) {
      std::string line = nextLine("the end of the frame");
      if (line.empty()) break;
      // A new echo inside a frame: the previous frame lost its end; start over.
      if (line.size() == echo.size() && isEcho(line)) {
        ++counters_.dropped_frames;
        echo = line;
        restarted = true;
        break;
      }
      if (frame.lines.size() >= kMaxFrameLines) {
        throw ScipError(ScipError::Kind::Malformed, device + ": " + echo + ": frame too long");
      }
      frame.lines.push_back(std::move(line));
    }
    if (restarted) continue;
    if (frame.lines.empty()) {
      throw ScipError(ScipError::Kind::Truncated, device + ": " + echo + ": frame has no status");
    }
    const std::string status_line = frame.lines.front();
    frame.lines.erase(frame.lines.begin());
    // Status "00P"; some firmware omits the sum on errors, so two characters are taken as is.
    if (status_line.size() == 3 && !sumMatches(status_line)) {
      throw ScipError(ScipError::Kind::Checksum,
                      device + ": " + echo + ": bad checksum on status " + quoted(status_line));
    }
    // One character without a sum: a SCIP 1.1 reply (spec §2), reported as such.
    if (status_line.size() != 3 && status_line.size() != 2 && status_line.size() != 1) {
      throw ScipError(ScipError::Kind::Malformed,
                      device + ": " + echo + ": bad status line " + quoted(status_line));
    }
    frame.status = status_line.substr(0, 2);
    return frame;
  }
}

ScipFrame ScipClient::command(const std::string& text, std::initializer_list<std::string_view> ok) {
  reader_.transport().write(text + "\n");
  ScipFrame frame = readFrame(text);
  for (const auto status : ok) {
    if (frame.status == status) return frame;
  }
  throw ScipError(ScipError::Kind::Status, reader_.transport().name() + ": " + text + ": status " +
                                               quoted(frame.status) + statusMeaning(text, frame.status));
}

std::map<std::string, std::string> ScipClient::keyValues(const ScipFrame& frame,
                                                         const std::string& command) {
  std::map<std::string, std::string> values;
  const std::string& device = reader_.transport().name();
  for (const auto& line : frame.lines) {
    if (line.size() < 3) {
      throw ScipError(ScipError::Kind::Malformed, device + ": " + command + ": short line " + quoted(line));
    }
    const std::string_view payload(line.data(), line.size() - 1);
    // Firmware differs on whether the ';' before the sum is summed: accept both.
    const bool sum_ok =
        scipChecksum(payload) == line.back() ||
        (payload.back() == ';' && scipChecksum(payload.substr(0, payload.size() - 1)) == line.back());
    if (!sum_ok) {
      throw ScipError(ScipError::Kind::Checksum, device + ": " + command + ": bad checksum on " + quoted(line));
    }
    const auto colon = payload.find(':');
    if (colon == std::string_view::npos || colon == 0 || payload.back() != ';') {
      throw ScipError(ScipError::Kind::Malformed,
                      device + ": " + command + ": expected KEY:value; in " + quoted(line));
    }
    values[std::string(payload.substr(0, colon))] =
        std::string(payload.substr(colon + 1, payload.size() - colon - 2));
  }
  return values;
}

bool ScipClient::connect() {
  Transport& transport = reader_.transport();
  stream_echo_.clear();
  transport.write("QT\n");
  const ScipFrame first = readFrame("QT");
  if (first.status == "00") return false;
  bool switched = false;
  if (first.status.size() == 1) {  // SCIP 1.1 answered
    transport.write("SCIP2.0\n");
    const ScipFrame reply = readFrame("SCIP2.0");
    if (reply.status != "0" && reply.status != "00") {
      throw ScipError(ScipError::Kind::Status,
                      transport.name() + ": SCIP2.0: status " + quoted(reply.status) +
                          ": the sensor would not switch to SCIP 2.0");
    }
    switched = true;
  } else if (first.status == "0E") {  // in time adjust mode (§8.6), which takes no QT
    transport.write("TM2\n");
    readFrame("TM2");
  } else {
    throw ScipError(ScipError::Kind::Status, transport.name() + ": QT: status " + quoted(first.status) +
                                                 statusMeaning("QT", first.status));
  }
  command("QT", {"00"});
  return switched;
}

std::map<std::string, std::string> ScipClient::versionInfo() {
  return keyValues(command("VV", {"00"}), "VV");
}

std::map<std::string, std::string> ScipClient::status() {
  return keyValues(command("II", {"00"}), "II");
}

ScipParameters ScipClient::parameters() {
  const auto values = keyValues(command("PP", {"00"}), "PP");
  const std::string& device = reader_.transport().name();
  auto number = [&](const char* key) {
    const auto found = values.find(key);
    if (found == values.end()) {
      throw ScipError(ScipError::Kind::Malformed, device + ": PP: no " + key + " field");
    }
    const std::string& text = found->second;
    std::uint32_t value = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size() || text.empty()) {
      throw ScipError(ScipError::Kind::Malformed,
                      device + ": PP: " + key + " is not a number: " + quoted(text));
    }
    return value;
  };
  ScipParameters parameters;
  if (const auto model = values.find("MODL"); model != values.end()) parameters.model = model->second;
  parameters.min_range_mm = number("DMIN");
  parameters.max_range_mm = number("DMAX");
  parameters.steps_per_revolution = number("ARES");
  parameters.first_step = number("AMIN");
  parameters.last_step = number("AMAX");
  parameters.front_step = number("AFRT");
  parameters.scan_rpm = number("SCAN");
  if (parameters.steps_per_revolution == 0 || parameters.first_step > parameters.last_step ||
      parameters.last_step >= parameters.steps_per_revolution || parameters.last_step > 9999 ||
      parameters.front_step < parameters.first_step || parameters.front_step > parameters.last_step ||
      parameters.min_range_mm >= parameters.max_range_mm || parameters.scan_rpm == 0) {
    throw ScipError(ScipError::Kind::Malformed, device + ": PP: inconsistent parameters (ARES " +
                                                    std::to_string(parameters.steps_per_revolution) +
                                                    ", AMIN..AMAX " + std::to_string(parameters.first_step) +
                                                    ".." + std::to_string(parameters.last_step) + ")");
  }
  parameters_ = parameters;
  return parameters;
}

void ScipClient::laserOn() { command("BM", {"00", "02"}); }
void ScipClient::stop() {
  stream_echo_.clear();
  command("QT", {"00"});
}
void ScipClient::reset() {
  stream_echo_.clear();
  command("RS", {"00"});
}

std::vector<ScipClient::TimeSample> ScipClient::timeSamples(int samples) {
  command("TM0", {"00", "02"});
  std::vector<TimeSample> result;
  Transport& transport = reader_.transport();
  for (int i = 0; i < samples; ++i) {
    transport.write("TM1\n");
    const double sent = transport.now();
    const ScipFrame frame = readFrame("TM1");
    const double received = transport.now();
    if (frame.status != "00") {
      throw ScipError(ScipError::Kind::Status, transport.name() + ": TM1: status " + quoted(frame.status));
    }
    if (frame.lines.size() != 1 || frame.lines[0].size() != 5 || !sumMatches(frame.lines[0])) {
      throw ScipError(ScipError::Kind::Checksum,
                      transport.name() + ": TM1: bad time line " +
                          quoted(frame.lines.empty() ? "" : frame.lines[0]));
    }
    const auto raw = scipDecode(std::string_view(frame.lines[0]).substr(0, 4));
    if (!raw) throw ScipError(ScipError::Kind::Malformed, transport.name() + ": TM1: bad time characters");
    result.push_back({0.5 * (sent + received), static_cast<double>(unwrapper_.unwrap(*raw)) * 1e-3,
                      received - sent});
  }
  command("TM2", {"00", "03"});
  return result;
}

ClockModel fitClock(const std::vector<ScipClient::TimeSample>& samples) {
  ClockModel model;
  if (samples.empty()) throw Error("time synchronisation: no TM samples");
  double mean_host = 0.0, mean_device = 0.0;
  for (const auto& sample : samples) {
    mean_host += sample.host_s;
    mean_device += sample.device_s;
  }
  mean_host /= static_cast<double>(samples.size());
  mean_device /= static_cast<double>(samples.size());
  double sxx = 0.0, sxy = 0.0;
  for (const auto& sample : samples) {
    sxx += (sample.host_s - mean_host) * (sample.host_s - mean_host);
    sxy += (sample.host_s - mean_host) * (sample.device_s - mean_device);
  }
  // A short span cannot tell drift from the 1 ms quantisation: assume rate 1 then.
  model.rate = sxx > 1e-4 ? sxy / sxx : 1.0;
  model.offset_s = mean_device - model.rate * mean_host;
  for (const auto& sample : samples) {
    const double residual = std::abs(model.toDevice(sample.host_s) - sample.device_s);
    // The round trip is host time; the residual and the bound are on the device's clock.
    model.max_residual_s = std::max(model.max_residual_s, residual + 0.5 * sample.round_trip_s * model.rate);
  }
  return model;
}

void ScipClient::startScans(std::uint32_t start_step, std::uint32_t end_step, std::uint32_t cluster,
                            bool three_characters, std::uint32_t count, std::uint32_t interval) {
  startStream(three_characters ? "MD" : "MS", start_step, end_step, cluster, count, interval);
}

void ScipClient::startIntensityScans(std::uint32_t start_step, std::uint32_t end_step, std::uint32_t cluster,
                                     std::uint32_t count, std::uint32_t interval) {
  startStream("ME", start_step, end_step, cluster, count, interval);
}

void ScipClient::startStream(const std::string& symbol, std::uint32_t start_step, std::uint32_t end_step,
                             std::uint32_t cluster, std::uint32_t count, std::uint32_t interval) {
  if (start_step > end_step || cluster > 99 || count > 99 || interval > 9) {
    throw Error(reader_.transport().name() + ": " + symbol +
                ": bad step range, cluster (1-99), count (0-99) or interval (0-9)");
  }
  const std::string text = symbol + decimal(start_step, 4) + decimal(end_step, 4) + decimal(cluster, 2) +
                           decimal(interval, 1) + decimal(count, 2);
  command(text, {"00"});
  stream_echo_ = text.substr(0, 13);  // the remaining-scan count changes from frame to frame
  stream_width_ = symbol == "MS" ? 2 : 3;
  stream_intensities_ = symbol == "ME";
  stream_start_ = start_step;
  stream_end_ = end_step;
  stream_cluster_ = std::max<std::uint32_t>(cluster, 1);  // §8.1: 00 and 01 alike
}

ScipScan ScipClient::nextScan(int max_drops) {
  if (stream_echo_.empty()) throw Error(reader_.transport().name() + ": no MD/MS scan running");
  std::optional<ScipError> last;
  for (int attempt = 0; attempt <= max_drops; ++attempt) {
    try {
      const ScipFrame frame = readFrame(stream_echo_);
      if (frame.status == "00") continue;  // the acknowledgement of MD itself
      if (frame.status != "99") {
        throw ScipError(ScipError::Kind::Status, reader_.transport().name() + ": " + frame.echo +
                                                     ": status " + quoted(frame.status) +
                                                     statusMeaning(frame.echo, frame.status));
      }
      ScipScan scan = decodeScan(frame, stream_width_, true, stream_intensities_);
      ++counters_.frames;
      return scan;
    } catch (const ScipError& error) {
      if (error.kind() == ScipError::Kind::Timeout) throw;
      ++counters_.dropped_frames;
      last = error;
    }
  }
  if (!last) {  // nothing but acknowledgements
    throw ScipError(ScipError::Kind::Malformed,
                    reader_.transport().name() + ": " + stream_echo_ + ": " +
                        std::to_string(max_drops + 1) + " frames in a row without scan data");
  }
  throw *last;
}

ScipScan ScipClient::singleScan(std::uint32_t start_step, std::uint32_t end_step,
                                std::uint32_t cluster, bool three_characters) {
  if (start_step > end_step || cluster > 99) {
    throw Error(reader_.transport().name() + ": GD: bad step range or cluster");
  }
  const std::string text = std::string(three_characters ? "GD" : "GS") + decimal(start_step, 4) +
                           decimal(end_step, 4) + decimal(cluster, 2);
  stream_start_ = start_step;
  stream_end_ = end_step;
  stream_cluster_ = std::max<std::uint32_t>(cluster, 1);
  const ScipFrame frame = command(text, {"00"});
  ScipScan scan = decodeScan(frame, three_characters ? 3 : 2, true);
  ++counters_.frames;
  return scan;
}

ScipScan ScipClient::decodeScan(const ScipFrame& frame, int width, bool has_timestamp, bool intensities) {
  const std::string& device = reader_.transport().name();
  const std::string where = device + ": " + frame.echo;
  std::size_t first_data = 0;
  ScipScan scan;
  if (has_timestamp) {
    if (frame.lines.empty()) throw ScipError(ScipError::Kind::Truncated, where + ": no timestamp");
    const std::string& stamp = frame.lines[0];
    if (stamp.size() != 5) throw ScipError(ScipError::Kind::Malformed, where + ": bad timestamp line " + quoted(stamp));
    if (!sumMatches(stamp)) throw ScipError(ScipError::Kind::Checksum, where + ": bad checksum on timestamp " + quoted(stamp));
    const auto raw = scipDecode(std::string_view(stamp).substr(0, 4));
    if (!raw) throw ScipError(ScipError::Kind::Malformed, where + ": bad timestamp characters");
    scan.timestamp_ms = unwrapper_.unwrap(*raw);
    first_data = 1;
  }
  std::string data;
  for (std::size_t i = first_data; i < frame.lines.size(); ++i) {
    const std::string& line = frame.lines[i];
    if (line.size() < 2 || line.size() > kMaxDataPayload + 1) {
      throw ScipError(ScipError::Kind::Malformed, where + ": data line " + std::to_string(i) +
                                                      " has " + std::to_string(line.size()) + " characters");
    }
    if (!sumMatches(line)) {
      throw ScipError(ScipError::Kind::Checksum,
                      where + ": bad checksum on data line " + std::to_string(i) + " " + quoted(line));
    }
    data.append(line, 0, line.size() - 1);
  }
  // One value per cluster (the last one may hold fewer steps); ME: a range and an intensity each.
  const std::size_t expected = (stream_end_ - stream_start_) / stream_cluster_ + 1;
  const std::size_t per_value = static_cast<std::size_t>(width) * (intensities ? 2 : 1);
  if (data.size() != expected * per_value) {
    throw ScipError(ScipError::Kind::Truncated,
                    where + ": " + std::to_string(data.size()) + " data characters, expected " +
                        std::to_string(expected * per_value));
  }
  auto values = scipDecodeValues(data, width);
  if (!values) throw ScipError(ScipError::Kind::Malformed, where + ": character outside the SCIP range");
  if (intensities) {
    for (std::size_t i = 0; i < values->size(); i += 2) {
      scan.ranges_mm.push_back((*values)[i]);
      scan.intensities.push_back((*values)[i + 1]);
    }
  } else {
    scan.ranges_mm = std::move(*values);
  }
  scan.start_step = stream_start_;
  scan.end_step = stream_end_;
  scan.cluster = stream_cluster_;
  return scan;
}

}  // namespace mlmap::driver
