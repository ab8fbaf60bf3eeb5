#include "cloud_values.hpp"

#include <cmath>

#include "file_bytes.hpp"
#include "number_text.hpp"

namespace mlmap::io {

double parseCoordinate(const TextLines& lines, std::string_view token, bool single_precision) {
  const double value = lines.parseDouble(token);
  if (!single_precision) return value;
  if (std::abs(value) > std::numeric_limits<float>::max()) {
    lines.fail("value does not fit a float: '" + std::string(token.substr(0, 40)) + "'");
  }
  return static_cast<float>(value);
}

std::vector<std::string_view> nextRowFields(TextLines& lines, std::uint64_t done,
                                            std::uint64_t count, std::string_view rows) {
  std::vector<std::string_view> fields;
  do {
    if (!lines.next()) {
      lines.fail("file ends after " + std::to_string(done) + " of " + std::to_string(count) + " " +
                 std::string(rows));
    }
    fields = lines.fields();
  } while (fields.empty());
  return fields;
}

void appendFloatXyz(std::string& out, const Point& point) {
  appendNumber(out, static_cast<float>(point.x()));
  out += ' ';
  appendNumber(out, static_cast<float>(point.y()));
  out += ' ';
  appendNumber(out, static_cast<float>(point.z()));
}

void storeFloatXyz(char* row, const Point& point) {
  storeLittleEndian(row, static_cast<float>(point.x()));
  storeLittleEndian(row + 4, static_cast<float>(point.y()));
  storeLittleEndian(row + 8, static_cast<float>(point.z()));
}

void requireLabelPerPoint(const std::filesystem::path& path, const Scan& scan) {
  if (!scan.labels.empty() && scan.labels.size() != scan.points.size()) {
    throw Error(path.string() + ": scan has " + std::to_string(scan.points.size()) +
                " points but " + std::to_string(scan.labels.size()) + " labels");
  }
}

}  // namespace mlmap::io
