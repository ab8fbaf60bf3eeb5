#include "ply_header.hpp"

#include <utility>

#include "file_bytes.hpp"
#include "mlmap/error.hpp"

namespace mlmap::io::ply {

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

double loadAsDouble(ScalarType type, const char* source) {
  switch (type) {
    case ScalarType::Float32: return loadLittleEndian<float>(source);
    case ScalarType::Float64: return loadLittleEndian<double>(source);
    default: return static_cast<double>(loadAsInteger(type, source));
  }
}

std::size_t Element::minimumRowBytes() const {
  std::size_t bytes = 0;
  for (const Property& property : properties) {
    bytes += sizeOf(property.list_count_type ? *property.list_count_type : property.type);
  }
  return bytes;
}

bool Element::hasLists() const {
  for (const Property& property : properties) {
    if (property.list_count_type) return true;
  }
  return false;
}

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

}  // namespace mlmap::io::ply
