// Internal to the PLY reader (ply.cpp): the header's model (elements, their properties and
// scalar types), read line by line with errors naming the line, and where a vertex's
// coordinates and label sit in it. In a namespace of its own: the PCD reader has a Header too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "text_lines.hpp"

namespace mlmap::io::ply {

enum class ScalarType { Int8, Uint8, Int16, Uint16, Int32, Uint32, Float32, Float64 };

// The type a header names ("float", "uchar", "int32", ...), if any.
std::optional<ScalarType> scalarTypeFromName(std::string_view name);
std::size_t sizeOf(ScalarType type);
bool isInteger(ScalarType type);
// Reads one integer scalar of `type` at `source` (bounds already checked), widened.
std::int64_t loadAsInteger(ScalarType type, const char* source);
// Any scalar, widened: every integer type fits a double exactly.
double loadAsDouble(ScalarType type, const char* source);

struct Property {
  std::string name;
  ScalarType type = ScalarType::Float32;       // item type for lists
  std::optional<ScalarType> list_count_type;   // set for list properties
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  std::size_t header_line = 0;

  // Bytes a binary row takes at least (lists counted as empty).
  std::size_t minimumRowBytes() const;
  bool hasLists() const;
};

enum class Format { Ascii, BinaryLittleEndian };

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
};

// Parses "ply" ... "end_header"; leaves `lines` on the end_header line.
Header parseHeader(TextLines& lines);

// Where x, y, z and the optional label sit in the vertex element.
struct VertexLayout {
  std::size_t x = 0, y = 0, z = 0;  // property indices
  std::optional<std::size_t> label;
};

// Throws mlmap::Error naming `source` and the element's header line where x, y or z is
// missing or not a float or double.
VertexLayout findVertexLayout(const Element& vertex, const std::string& source);

}  // namespace mlmap::io::ply
