// Internal helper for the point-cloud formats (PLY, PCD): the rules their readers
// and writers share for coordinates and labels.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

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

// Moves `lines` to the next line that has fields and returns them; at the end of
// the file fails with "file ends after <done> of <count> <rows>".
std::vector<std::string_view> nextRowFields(TextLines& lines, std::uint64_t done,
                                            std::uint64_t count, std::string_view rows);

// Writers keep coordinates as float: "x y z" as text, or 12 little-endian bytes.
void appendFloatXyz(std::string& out, const Point& point);
void storeFloatXyz(char* row, const Point& point);

// Throws mlmap::Error naming `path` unless the scan has no labels or one per point.
void requireLabelPerPoint(const std::filesystem::path& path, const Scan& scan);

}  // namespace mlmap::io
