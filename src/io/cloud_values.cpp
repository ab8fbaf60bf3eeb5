#include "cloud_values.hpp"

#include <cmath>

namespace mlmap::io {

double parseCoordinate(const TextLines& lines, std::string_view token, bool single_precision) {
  const double value = lines.parseDouble(token);
  if (!single_precision) return value;
  if (std::abs(value) > std::numeric_limits<float>::max()) {
    lines.fail("value does not fit a float: '" + std::string(token.substr(0, 40)) + "'");
  }
  return static_cast<float>(value);
}

void requireLabelPerPoint(const std::filesystem::path& path, const Scan& scan) {
  if (!scan.labels.empty() && scan.labels.size() != scan.points.size()) {
    throw Error(path.string() + ": scan has " + std::to_string(scan.points.size()) +
                " points but " + std::to_string(scan.labels.size()) + " labels");
  }
}

}  // namespace mlmap::io
