// Internal helper for the point-cloud formats (PLY, PCD): the rules their readers
// and writers share for coordinates and labels.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>

#include "mlmap/error.hpp"
#include "mlmap/scan.hpp"
#include "text_lines.hpp"

namespace mlmap::io {

// A label as read (any integer width) narrowed to int32; `where` builds the
// location for the error message only when the label is out of range.
template <typename Where>
std::int32_t checkedLabel(std::int64_t value, const Where& where) {
  if (value < std::numeric_limits<std::int32_t>::min() ||
      value > std::numeric_limits<std::int32_t>::max()) {
    throw Error(where() + ": label " + std::to_string(value) + " does not fit a 32-bit integer");
  }
  return static_cast<std::int32_t>(value);
}

// "file:line" of the current text line, for checkedLabel.
inline std::string lineWhere(const TextLines& lines) {
  return lines.sourceName() + ":" + std::to_string(lines.lineNumber());
}

// A coordinate from a text body. Values of a float field are rounded to float, so
// ascii and binary files give the same coordinates.
double parseCoordinate(const TextLines& lines, std::string_view token, bool single_precision);

// Throws mlmap::Error naming `path` unless the scan has no labels or one per point.
void requireLabelPerPoint(const std::filesystem::path& path, const Scan& scan);

}  // namespace mlmap::io
