// Internal to the PCD reader and writer (pcd.cpp): the header's model, read line by line
// and checked as a whole (the sizes, types and counts the body is then decoded by), and
// the header the writer puts before its points.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mlmap/scan.hpp"
#include "text_lines.hpp"

namespace mlmap::io {

struct Field {
  std::string name;
  std::size_t size = 4;    // bytes per value: 1, 2, 4 or 8
  char type = 'F';         // F float, I signed, U unsigned
  std::size_t count = 1;   // values per point
  std::size_t offset = 0;  // bytes before this field in a packed point
};

enum class Encoding { Ascii, Binary, BinaryCompressed };

struct Header {
  std::vector<Field> fields;
  std::uint64_t points = 0;
  std::uint64_t rows = 1;  // HEIGHT: more than one row is an organized cloud (a depth image)
  std::size_t point_bytes = 0;
  Pose viewpoint = Pose::Identity();
  Encoding encoding = Encoding::Ascii;
  std::size_t x = 0, y = 0, z = 0;  // field indices
  std::optional<std::size_t> label;
};

// Reads header lines up to and including DATA, validates them together; errors name the line.
Header parsePcdHeader(TextLines& lines);

// PCD v0.7, one point per row: x y z (float) and, with labels, a 4-byte label (signed or
// not), the scan's pose as VIEWPOINT.
std::string makePcdHeader(const Scan& scan, bool with_labels, bool signed_labels, Encoding encoding);

}  // namespace mlmap::io
