// SCIP 2.0's encoding, free of any device: the 6-bit character codes, the line sum, the
// status codes' meanings and the 24-bit timestamp's wrap (the client is in scip.cpp).
#include "mlmap/driver/scip.hpp"

#include <cstdint>
#include <numbers>
#include <string>

namespace mlmap::driver {

std::string scipStatusMeaning(std::string_view command, std::string_view status) {
  const std::string_view symbol = command.substr(0, 2);
  const bool scan = symbol == "MD" || symbol == "MS" || symbol == "ME" || symbol == "GD" || symbol == "GS";
  if (scan) {  // §8.1, §8.2
    if (status == "01") return "starting step has a non-numeric value";
    if (status == "02") return "end step has a non-numeric value";
    if (status == "03") return "cluster count has a non-numeric value";
    if (status == "04") return "end step is out of range";
    if (status == "05") return "end step is smaller than the starting step";
    if (status == "06") return "scan interval has a non-numeric value";
    if (status == "07") return "number of scans has a non-numeric value";
    if (status == "10") return "laser is off";
    if (status == "98") return "resumption after confirming normal laser operation";
    if (status.size() == 2 && status[0] >= '2' && status[0] <= '4' && status[1] >= '0' && status[1] <= '9') {
      return "processing stopped to verify an error";
    }
  }
  if (symbol == "BM") {  // §8.3
    if (status == "01") return "unable to control the laser (malfunction)";
    if (status == "02") return "laser is already on";
  }
  if (symbol == "TM") {  // §8.6
    if (status == "01") return "invalid control code";
    if (status == "02") return "adjust mode is already on";
    if (status == "03") return "adjust mode is already off";
    if (status == "04") return "adjust mode is off when the time was requested";
  }
  // §9, any command
  if (status == "0A") return "unable to create transmission data or reply";
  if (status == "0B") return "buffer shortage, or a command repeated that is already being processed";
  if (status == "0C") return "command with insufficient parameters (1)";
  if (status == "0D") return "undefined command (1)";
  if (status == "0E") return "undefined command (2)";
  if (status == "0F") return "command with insufficient parameters (2)";
  if (status == "0G") return "string characters exceed 16 letters";
  if (status == "0H") return "string characters have invalid letters";
  if (status == "0I") return "sensor is in firmware update mode";
  if (status.size() == 2 && status[0] >= '5' && status[0] <= '9' && status != "99") {
    return "hardware trouble (laser, motor)";
  }
  if (status.size() == 1) return "a SCIP 1.1 status: the sensor is not in SCIP 2.0";
  return "";
}

char scipChecksum(std::string_view text) {
  unsigned sum = 0;
  for (const char c : text) sum += static_cast<unsigned char>(c);
  return static_cast<char>((sum & 0x3Fu) + 0x30u);
}

std::optional<std::uint32_t> scipDecode(std::string_view characters) {
  if (characters.size() < 2 || characters.size() > 4) return std::nullopt;
  std::uint32_t value = 0;
  for (const char c : characters) {
    const int digit = static_cast<unsigned char>(c) - 0x30;
    if (digit < 0 || digit > 0x3F) return std::nullopt;
    value = (value << 6) | static_cast<std::uint32_t>(digit);
  }
  return value;
}

std::string scipEncode(std::uint32_t value, int width) {
  if (width < 1 || width > 5 || (width < 5 && value >> (6 * width) != 0)) {
    throw Error("SCIP: " + std::to_string(value) + " does not fit in " + std::to_string(width) +
                " characters");
  }
  std::string out(static_cast<std::size_t>(width), '0');
  for (int i = width - 1; i >= 0; --i) {
    out[static_cast<std::size_t>(i)] = static_cast<char>(0x30 + (value & 0x3F));
    value >>= 6;
  }
  return out;
}

std::optional<std::vector<std::uint32_t>> scipDecodeValues(std::string_view characters, int width) {
  if (width < 2 || width > 4 || characters.size() % static_cast<std::size_t>(width) != 0) {
    return std::nullopt;
  }
  std::vector<std::uint32_t> values;
  values.reserve(characters.size() / static_cast<std::size_t>(width));
  for (std::size_t i = 0; i < characters.size(); i += static_cast<std::size_t>(width)) {
    const auto value = scipDecode(characters.substr(i, static_cast<std::size_t>(width)));
    if (!value) return std::nullopt;
    values.push_back(*value);
  }
  return values;
}

std::string scipLine(std::string_view payload) {
  std::string line(payload);
  line += scipChecksum(payload);
  line += '\n';
  return line;
}

double ScipParameters::stepAngle(double step) const {
  return (step - static_cast<double>(front_step)) * 2.0 * std::numbers::pi /
         static_cast<double>(steps_per_revolution);
}

std::uint64_t TimestampUnwrapper::unwrap(std::uint32_t raw_ms) {
  constexpr std::uint64_t kWrap = 1ull << 24;
  raw_ms &= kWrap - 1;
  if (!last_) {
    last_ = raw_ms;
    return raw_ms;
  }
  std::uint64_t base = *last_ & ~(kWrap - 1);
  std::uint64_t candidate = base + raw_ms;
  // Nearest to the last value: a jump back of more than half the range is a wrap.
  if (candidate + kWrap / 2 < *last_) candidate += kWrap;
  else if (candidate > *last_ + kWrap / 2 && candidate >= kWrap) candidate -= kWrap;
  last_ = candidate;
  return candidate;
}

}  // namespace mlmap::driver
