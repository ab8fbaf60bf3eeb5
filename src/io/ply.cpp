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
#include "ply_header.hpp"
#include "text_lines.hpp"

namespace mlmap::io {
namespace {

using namespace ply;

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
