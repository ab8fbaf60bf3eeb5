// PLY reader and writer. The whole file is read into memory once; the header is
// parsed line by line (so errors name the line), the binary body is decoded with
// explicit bounds checks and memcpy (rows are unaligned), every error names the
// file and the line (header, ascii body) or the byte offset (binary body).
#include "mlmap/io/ply.hpp"

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cloud_values.hpp"
#include "file_bytes.hpp"
#include "mlmap/error.hpp"
#include "number_text.hpp"
#include "text_lines.hpp"

namespace mlmap::io {
namespace {

// ---------------------------------------------------------------- header model

enum class ScalarType { Int8, Uint8, Int16, Uint16, Int32, Uint32, Float32, Float64 };

std::optional<ScalarType> scalarTypeFromName(std::string_view name) {
  if (name == "char" || name == "int8") return ScalarType::Int8;
  if (name == "uchar" || name == "uint8") return ScalarType::Uint8;
  if (name == "short" || name == "int16") return ScalarType::Int16;
  if (name == "ushort" || name == "uint16") return ScalarType::Uint16;
  if (name == "int" || name == "int32") return ScalarType::Int32;
  if (name == "uint" || name == "uint32") return ScalarType::Uint32;
  if (name == "float" || name == "float32") return ScalarType::Float32;
  if (name == "double" || name == "float64") return ScalarType::Float64;
  return std::nullopt;
}

std::size_t sizeOf(ScalarType type) {
  switch (type) {
    case ScalarType::Int8:
    case ScalarType::Uint8: return 1;
    case ScalarType::Int16:
    case ScalarType::Uint16: return 2;
    case ScalarType::Int32:
    case ScalarType::Uint32:
    case ScalarType::Float32: return 4;
    case ScalarType::Float64: return 8;
  }
  return 0;
}

bool isInteger(ScalarType type) {
  return type != ScalarType::Float32 && type != ScalarType::Float64;
}

// Reads one integer scalar of `type` at `source` (bounds already checked), widened.
std::int64_t loadAsInteger(ScalarType type, const char* source) {
  switch (type) {
    case ScalarType::Int8: return static_cast<std::int8_t>(*source);
    case ScalarType::Uint8: return static_cast<std::uint8_t>(*source);
    case ScalarType::Int16: return loadLittleEndian<std::int16_t>(source);
    case ScalarType::Uint16: return loadLittleEndian<std::uint16_t>(source);
    case ScalarType::Int32: return loadLittleEndian<std::int32_t>(source);
    case ScalarType::Uint32: return loadLittleEndian<std::uint32_t>(source);
    default: return 0;  // only called for integer types
  }
}

// Any scalar, widened: every integer type fits a double exactly.
double loadAsDouble(ScalarType type, const char* source) {
  switch (type) {
    case ScalarType::Float32: return loadLittleEndian<float>(source);
    case ScalarType::Float64: return loadLittleEndian<double>(source);
    default: return static_cast<double>(loadAsInteger(type, source));
  }
}

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
  std::size_t minimumRowBytes() const {
    std::size_t bytes = 0;
    for (const Property& property : properties) {
      bytes += sizeOf(property.list_count_type ? *property.list_count_type : property.type);
    }
    return bytes;
  }
  bool hasLists() const {
    for (const Property& property : properties) {
      if (property.list_count_type) return true;
    }
    return false;
  }
};

enum class Format { Ascii, BinaryLittleEndian };

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
};

// Parses "ply" ... "end_header"; leaves `lines` on the end_header line.
Header parseHeader(TextLines& lines) {
  if (!lines.next() || lines.fields() != std::vector<std::string_view>{"ply"}) {
    lines.fail("not a PLY file (the first line must be 'ply')");
  }
  Header header;
  bool have_format = false;
  while (true) {
    if (!lines.next()) lines.fail("file ends inside the header (no 'end_header')");
    const auto fields = lines.fields();
    if (fields.empty()) continue;
    const std::string_view keyword = fields[0];
    if (keyword == "end_header") break;
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "format") {
      if (fields.size() != 3) lines.fail("expected 'format <encoding> 1.0'");
      if (fields[2] != "1.0") lines.fail("unsupported PLY version '" + std::string(fields[2]) + "'");
      if (fields[1] == "ascii") {
        header.format = Format::Ascii;
      } else if (fields[1] == "binary_little_endian") {
        header.format = Format::BinaryLittleEndian;
      } else if (fields[1] == "binary_big_endian") {
        lines.fail("unsupported PLY encoding binary_big_endian (convert to binary_little_endian)");
      } else {
        lines.fail("unknown PLY format '" + std::string(fields[1]) + "'");
      }
      have_format = true;
    } else if (keyword == "element") {
      if (fields.size() != 3) lines.fail("expected 'element <name> <count>'");
      const std::int64_t count = lines.parseInt(fields[2]);
      if (count < 0) lines.fail("negative element count");
      header.elements.push_back(
          {std::string(fields[1]), static_cast<std::uint64_t>(count), {}, lines.lineNumber()});
    } else if (keyword == "property") {
      if (header.elements.empty()) lines.fail("property before any element");
      Property property;
      if (fields.size() == 5 && fields[1] == "list") {
        const auto count_type = scalarTypeFromName(fields[2]);
        const auto item_type = scalarTypeFromName(fields[3]);
        if (!count_type || !item_type) lines.fail("unknown property type in list");
        if (!isInteger(*count_type)) lines.fail("list count type must be an integer type");
        property = {std::string(fields[4]), *item_type, count_type};
      } else if (fields.size() == 3) {
        const auto type = scalarTypeFromName(fields[1]);
        if (!type) lines.fail("unknown property type '" + std::string(fields[1]) + "'");
        property = {std::string(fields[2]), *type, std::nullopt};
      } else {
        lines.fail("expected 'property <type> <name>' or 'property list <type> <type> <name>'");
      }
      header.elements.back().properties.push_back(std::move(property));
    } else {
      lines.fail("unknown header keyword '" + std::string(keyword) + "'");
    }
  }
  if (!have_format) lines.fail("header has no 'format' line");
  return header;
}

// Where x, y, z and the optional label sit in the vertex element.
struct VertexLayout {
  std::size_t x = 0, y = 0, z = 0;  // property indices
  std::optional<std::size_t> label;
};

VertexLayout findVertexLayout(const Element& vertex, const std::string& source) {
  std::optional<std::size_t> x, y, z;
  VertexLayout layout;
  for (std::size_t i = 0; i < vertex.properties.size(); ++i) {
    const Property& property = vertex.properties[i];
    const bool scalar = !property.list_count_type;
    if (property.name == "label") {
      // Float or list labels are not ours to interpret: ignored.
      if (scalar && isInteger(property.type) && !layout.label) layout.label = i;
      continue;
    }
    std::optional<std::size_t>* coordinate = property.name == "x"   ? &x
                                              : property.name == "y" ? &y
                                              : property.name == "z" ? &z
                                                                     : nullptr;
    if (coordinate == nullptr || *coordinate) continue;
    if (!scalar || isInteger(property.type)) {
      throw Error(source + ":" + std::to_string(vertex.header_line) + ": vertex property '" +
                  property.name + "' must be float or double");
    }
    *coordinate = i;
  }
  if (!x || !y || !z) {
    throw Error(source + ":" + std::to_string(vertex.header_line) +
                ": vertex element lacks property x, y or z");
  }
  layout.x = *x;
  layout.y = *y;
  layout.z = *z;
  return layout;
}

// ---------------------------------------------------------------- binary body

class BinaryBody {
 public:
  BinaryBody(const std::string& bytes, std::size_t offset, std::string source)
      : bytes_(bytes), offset_(offset), source_(std::move(source)) {}

  std::size_t offset() const { return offset_; }
  std::size_t remaining() const { return bytes_.size() - offset_; }
  const char* at(std::size_t offset) const { return bytes_.data() + offset; }
  std::string where(std::size_t byte) const { return source_ + ": byte " + std::to_string(byte); }

  [[noreturn]] void truncated(const Element& element, std::uint64_t index) const {
    throw Error(where(bytes_.size()) + ": data ends inside " + element.name + " " +
                std::to_string(index) + " (" + std::to_string(element.count) + " " +
                element.name + " expected)");
  }

  // Skips one property of one row, checking every read.
  void skipProperty(const Property& property, const Element& element, std::uint64_t index) {
    if (!property.list_count_type) {
      advance(sizeOf(property.type), element, index);
      return;
    }
    const std::size_t count_offset = offset_;
    advance(sizeOf(*property.list_count_type), element, index);
    const std::int64_t count = loadAsInteger(*property.list_count_type, at(count_offset));
    if (count < 0) throw Error(where(count_offset) + ": negative list length");
    const std::uint64_t item_bytes = static_cast<std::uint64_t>(count) * sizeOf(property.type);
    if (item_bytes > remaining()) truncated(element, index);
    offset_ += item_bytes;
  }

  void skipElement(const Element& element) {
    if (element.properties.empty()) return;
    const std::size_t row_bytes = element.minimumRowBytes();
    if (element.count > remaining() / row_bytes) truncated(element, remaining() / row_bytes);
    if (!element.hasLists()) {
      offset_ += element.count * row_bytes;
      return;
    }
    for (std::uint64_t i = 0; i < element.count; ++i) {
      for (const Property& property : element.properties) skipProperty(property, element, i);
    }
  }

  void advance(std::size_t bytes, const Element& element, std::uint64_t index) {
    if (bytes > remaining()) truncated(element, index);
    offset_ += bytes;
  }

 private:
  const std::string& bytes_;
  std::size_t offset_;
  std::string source_;
};

void readBinaryVertices(BinaryBody& body, const Element& vertex, const VertexLayout& layout,
                        Scan& scan) {
  // Rejects absurd counts before allocating: every row takes at least this much.
  const std::size_t min_row_bytes = vertex.minimumRowBytes();
  if (vertex.count > body.remaining() / min_row_bytes) {
    body.truncated(vertex, body.remaining() / min_row_bytes);
  }
  const auto count = static_cast<std::size_t>(vertex.count);
  scan.points.resize(count);
  if (layout.label) scan.labels.resize(count);

  std::vector<std::size_t> property_offsets(vertex.properties.size());
  const auto& properties = vertex.properties;
  const auto decode = [&](std::size_t index, std::size_t row_start) {
    const ScalarType x_type = properties[layout.x].type;
    const ScalarType y_type = properties[layout.y].type;
    const ScalarType z_type = properties[layout.z].type;
    Point point(loadAsDouble(x_type, body.at(row_start + property_offsets[layout.x])),
                loadAsDouble(y_type, body.at(row_start + property_offsets[layout.y])),
                loadAsDouble(z_type, body.at(row_start + property_offsets[layout.z])));
    if (!point.allFinite()) {
      throw Error(body.where(row_start) + ": vertex " + std::to_string(index) +
                  " has a non-finite coordinate");
    }
    scan.points[index] = point;
    if (layout.label) {
      const std::size_t label_offset = row_start + property_offsets[*layout.label];
      scan.labels[index] = checkedLabel(
          loadAsInteger(properties[*layout.label].type, body.at(label_offset)),
          [&] { return body.where(label_offset); });
    }
  };

  if (!vertex.hasLists()) {
    // Fixed stride: the size check above covered every row.
    std::size_t offset = 0;
    for (std::size_t i = 0; i < properties.size(); ++i) {
      property_offsets[i] = offset;
      offset += sizeOf(properties[i].type);
    }
    const std::size_t start = body.offset();
    for (std::size_t i = 0; i < count; ++i) decode(i, start + i * min_row_bytes);
    body.advance(count * min_row_bytes, vertex, count);
    return;
  }
  // Rows of varying length: note each property's offset while skipping the row.
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t row_start = body.offset();
    for (std::size_t p = 0; p < properties.size(); ++p) {
      property_offsets[p] = body.offset() - row_start;
      body.skipProperty(properties[p], vertex, i);
    }
    decode(i, row_start);
  }
}

// ---------------------------------------------------------------- ascii body

// Skips `count` rows of a non-vertex element: one element per line.
void skipAsciiElement(TextLines& lines, const Element& element) {
  if (element.properties.empty()) return;  // rows without values take no line
  const std::string rows = element.name + " lines";
  for (std::uint64_t i = 0; i < element.count; ++i) nextRowFields(lines, i, element.count, rows);
}

void readAsciiVertices(TextLines& lines, const Element& vertex, const VertexLayout& layout,
                       std::size_t remaining_bytes, Scan& scan) {
  // Each value takes at least two characters (digit and separator): a count the
  // file cannot hold is not reserved for.
  const std::size_t min_line_bytes = 2 * vertex.properties.size();
  scan.points.reserve(std::min<std::uint64_t>(vertex.count, remaining_bytes / min_line_bytes + 1));
  for (std::uint64_t i = 0; i < vertex.count; ++i) {
    const auto fields = nextRowFields(lines, i, vertex.count, "vertex lines");
    std::size_t field = 0;
    Point point = Point::Zero();
    std::int32_t label = 0;
    for (std::size_t p = 0; p < vertex.properties.size(); ++p) {
      const Property& property = vertex.properties[p];
      if (field >= fields.size()) {
        lines.fail("vertex line has too few values (" + std::to_string(fields.size()) + ")");
      }
      if (property.list_count_type) {
        const std::int64_t length = lines.parseInt(fields[field++]);
        if (length < 0 || static_cast<std::uint64_t>(length) > fields.size() - field) {
          lines.fail("list length " + std::to_string(length) + " does not match the line");
        }
        field += static_cast<std::size_t>(length);
        continue;
      }
      const std::string_view value = fields[field++];
      const bool single_precision = property.type == ScalarType::Float32;
      if (p == layout.x) point.x() = parseCoordinate(lines, value, single_precision);
      else if (p == layout.y) point.y() = parseCoordinate(lines, value, single_precision);
      else if (p == layout.z) point.z() = parseCoordinate(lines, value, single_precision);
      else if (layout.label && p == *layout.label) {
        label = checkedLabel(lines.parseInt(value), [&] { return lineWhere(lines); });
      }
    }
    if (field != fields.size()) {
      lines.fail("vertex line has " + std::to_string(fields.size()) + " values, expected " +
                 std::to_string(field));
    }
    scan.points.push_back(point);
    if (layout.label) scan.labels.push_back(label);
  }
}

}  // namespace

Scan readPly(const std::filesystem::path& path) {
  const std::string source = path.string();
  InMemoryFile file(path);
  const std::string& bytes = file.bytes();
  TextLines lines(file.stream(), source);
  const Header header = parseHeader(lines);

  const Element* vertex = nullptr;
  for (const Element& element : header.elements) {
    if (element.name == "vertex") {
      vertex = &element;
      break;
    }
  }
  if (vertex == nullptr) lines.fail("header has no 'element vertex'");
  const VertexLayout layout = findVertexLayout(*vertex, source);

  const std::size_t body_start = file.offset();
  Scan scan;
  if (header.format == Format::Ascii) {
    for (const Element& element : header.elements) {
      if (&element == vertex) break;
      skipAsciiElement(lines, element);
    }
    readAsciiVertices(lines, *vertex, layout, bytes.size() - body_start, scan);
  } else {
    BinaryBody body(bytes, body_start, source);
    for (const Element& element : header.elements) {
      if (&element == vertex) break;
      body.skipElement(element);
    }
    readBinaryVertices(body, *vertex, layout, scan);
  }
  // Elements after the vertices (faces, edges) are not needed.
  return scan;
}

void writePly(const std::filesystem::path& path, const Scan& scan, PlyEncoding encoding) {
  requireLabelPerPoint(path, scan);
  const bool with_labels = !scan.labels.empty();
  std::string out;
  out += "ply\nformat ";
  out += encoding == PlyEncoding::Ascii ? "ascii" : "binary_little_endian";
  out += " 1.0\ncomment written by mlmap\nelement vertex " + std::to_string(scan.size()) +
         "\nproperty float x\nproperty float y\nproperty float z\n";
  if (with_labels) out += "property int label\n";
  out += "end_header\n";

  if (encoding == PlyEncoding::Ascii) {
    out.reserve(out.size() + scan.size() * (with_labels ? 48 : 40));
    for (std::size_t i = 0; i < scan.size(); ++i) {
      appendFloatXyz(out, scan.points[i]);
      if (with_labels) {
        out += ' ';
        appendNumber(out, scan.labels[i]);
      }
      out += '\n';
    }
  } else {
    const std::size_t row_bytes = with_labels ? 16 : 12;
    const std::size_t header_bytes = out.size();
    out.resize(header_bytes + scan.size() * row_bytes);
    char* row = out.data() + header_bytes;
    for (std::size_t i = 0; i < scan.size(); ++i, row += row_bytes) {
      storeFloatXyz(row, scan.points[i]);
      if (with_labels) storeLittleEndian(row + 12, scan.labels[i]);
    }
  }
  writeWholeFile(path, out);
}

}  // namespace mlmap::io
