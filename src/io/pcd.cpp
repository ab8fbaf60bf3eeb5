// PCD reader and writer (PCL's format, v0.7 and the older headers PCL still
// reads). The whole file is read into memory once; the header is parsed line by
// line (errors name the line), binary bodies are decoded with explicit bounds
// checks and memcpy (points are packed, so unaligned), errors in them name the
// byte offset. Every size a header claims is checked against the bytes actually
// present before anything is allocated for it.
#include "mlmap/io/pcd.hpp"

#include <lzf.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cloud_values.hpp"
#include "file_bytes.hpp"
#include "mlmap/error.hpp"
#include "number_text.hpp"
#include "pcd_header.hpp"
#include "text_lines.hpp"

namespace mlmap::io {
namespace {

// PCD binary data is little-endian in practice (PCL writes host order on x86/ARM).

double loadCoordinate(const Field& field, const char* source) {
  return field.size == 4 ? static_cast<double>(loadLittleEndian<float>(source))
                         : loadLittleEndian<double>(source);
}

std::int64_t loadInteger(const Field& field, const char* source) {
  const bool is_signed = field.type == 'I';
  switch (field.size) {
    case 1:
      return is_signed ? std::int64_t{static_cast<std::int8_t>(*source)}
                       : std::int64_t{static_cast<std::uint8_t>(*source)};
    case 2:
      return is_signed ? std::int64_t{loadLittleEndian<std::int16_t>(source)}
                       : std::int64_t{loadLittleEndian<std::uint16_t>(source)};
    case 4:
      return is_signed ? std::int64_t{loadLittleEndian<std::int32_t>(source)}
                       : std::int64_t{loadLittleEndian<std::uint32_t>(source)};
    default: {
      if (is_signed) return loadLittleEndian<std::int64_t>(source);
      const auto value = loadLittleEndian<std::uint64_t>(source);
      // Saturates; checkedLabel rejects anything that large anyway.
      return value > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())
                 ? std::numeric_limits<std::int64_t>::max()
                 : static_cast<std::int64_t>(value);
    }
  }
}

std::string byteWhere(const std::string& source, std::size_t byte) {
  return source + ": byte " + std::to_string(byte);
}

// Where the x, y, z and label values of point i sit: `base[k] + i * stride[k]`.
// Packed rows (binary) and field-by-field blocks (binary_compressed) differ only here.
struct Layout {
  const char* base[4];       // x, y, z, label
  std::size_t stride[4];
};

// `where` names the location of a bad value for the error message.
template <typename Where>
void decodePoints(const Header& header, const Layout& layout, const Where& where, Scan& scan) {
  const Field& fx = header.fields[header.x];
  const Field& fy = header.fields[header.y];
  const Field& fz = header.fields[header.z];
  const auto count = static_cast<std::size_t>(header.points);
  scan.points.reserve(count);
  if (header.label) scan.labels.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const Point point(loadCoordinate(fx, layout.base[0] + i * layout.stride[0]),
                      loadCoordinate(fy, layout.base[1] + i * layout.stride[1]),
                      loadCoordinate(fz, layout.base[2] + i * layout.stride[2]));
    if (!point.allFinite()) continue;  // organized clouds mark "no return" with NaN
    scan.points.push_back(point);
    if (header.label) {
      const char* label = layout.base[3] + i * layout.stride[3];
      scan.labels.push_back(checkedLabel(loadInteger(header.fields[*header.label], label),
                                          [&] { return where(label); }));
    }
  }
}

void readBinary(const Header& header, const std::string& bytes, std::size_t start,
                const std::string& source, Scan& scan) {
  const std::size_t remaining = bytes.size() - start;
  if (header.points > remaining / header.point_bytes) {
    throw Error(byteWhere(source, bytes.size()) + ": data ends inside point " +
                std::to_string(remaining / header.point_bytes) + " (" +
                std::to_string(header.points) + " points of " + std::to_string(header.point_bytes) +
                " bytes expected from byte " + std::to_string(start) + ")");
  }
  const char* body = bytes.data() + start;
  Layout layout{};
  const std::size_t indices[4] = {header.x, header.y, header.z, header.label.value_or(header.x)};
  for (int k = 0; k < 4; ++k) {
    layout.base[k] = body + header.fields[indices[k]].offset;
    layout.stride[k] = header.point_bytes;
  }
  decodePoints(header, layout,
               [&](const char* at) { return byteWhere(source, static_cast<std::size_t>(at - bytes.data())); },
               scan);
}

// LZF output is at most 88 times its input (a 3-byte back reference expands to
// 264 bytes), so a declared size beyond that is a lie we need not allocate for.
constexpr std::uint64_t kMaxLzfExpansion = 88;

void readBinaryCompressed(const Header& header, const std::string& bytes, std::size_t start,
                          const std::string& source, Scan& scan) {
  if (header.points == 0 && bytes.size() - start < 8) return;  // nothing to compress
  if (bytes.size() - start < 8) {
    throw Error(byteWhere(source, bytes.size()) +
                ": data ends before the compressed and uncompressed sizes (expected " +
                std::to_string(header.points) + " points)");
  }
  const auto compressed_bytes = loadLittleEndian<std::uint32_t>(bytes.data() + start);
  const auto uncompressed_bytes = loadLittleEndian<std::uint32_t>(bytes.data() + start + 4);
  const std::uint64_t expected_bytes =
      header.points > std::numeric_limits<std::uint32_t>::max() / header.point_bytes
          ? std::numeric_limits<std::uint64_t>::max()
          : header.points * header.point_bytes;
  if (uncompressed_bytes != expected_bytes) {
    throw Error(byteWhere(source, start + 4) + ": declared uncompressed size " +
                std::to_string(uncompressed_bytes) + " is not " + std::to_string(header.points) +
                " points * " + std::to_string(header.point_bytes) + " bytes");
  }
  const std::size_t data_start = start + 8;
  if (compressed_bytes > bytes.size() - data_start) {
    throw Error(byteWhere(source, bytes.size()) + ": compressed data ends after " +
                std::to_string(bytes.size() - data_start) + " of " +
                std::to_string(compressed_bytes) + " bytes (from byte " +
                std::to_string(data_start) + ", " + std::to_string(header.points) +
                " points expected)");
  }
  if (uncompressed_bytes == 0) return;
  if (uncompressed_bytes / kMaxLzfExpansion > compressed_bytes) {
    throw Error(byteWhere(source, start) + ": " + std::to_string(compressed_bytes) +
                " compressed bytes cannot hold " + std::to_string(uncompressed_bytes) + " bytes");
  }
  std::string unpacked(uncompressed_bytes, '\0');
  const unsigned int produced = lzf_decompress(bytes.data() + data_start, compressed_bytes,
                                               unpacked.data(), uncompressed_bytes);
  if (produced != uncompressed_bytes) {
    throw Error(byteWhere(source, data_start) + ": LZF data does not decompress to the declared " +
                std::to_string(uncompressed_bytes) + " bytes");
  }
  // Field by field: all values of field 0, then all of field 1, ...
  Layout layout{};
  const std::size_t indices[4] = {header.x, header.y, header.z, header.label.value_or(header.x)};
  for (int k = 0; k < 4; ++k) {
    const Field& field = header.fields[indices[k]];
    layout.base[k] = unpacked.data() + header.points * field.offset;
    layout.stride[k] = field.size;
  }
  decodePoints(header, layout,
               [&](const char* at) {
                 return source + ": decompressed byte " + std::to_string(at - unpacked.data());
               },
               scan);
}

bool isNanToken(std::string_view token) {
  if (!token.empty() && (token.front() == '-' || token.front() == '+')) token.remove_prefix(1);
  return token.size() == 3 && (token[0] | 0x20) == 'n' && (token[1] | 0x20) == 'a' &&
         (token[2] | 0x20) == 'n';
}

void readAscii(const Header& header, TextLines& lines, std::size_t remaining_bytes, Scan& scan) {
  std::size_t values_per_point = 0;
  for (const Field& field : header.fields) values_per_point += field.count;
  // Column of each field's first value on a line.
  std::vector<std::size_t> column(header.fields.size());
  for (std::size_t i = 1; i < header.fields.size(); ++i) {
    column[i] = column[i - 1] + header.fields[i - 1].count;
  }
  // Each value takes at least two characters: never reserve more than the file holds.
  scan.points.reserve(std::min<std::uint64_t>(header.points, remaining_bytes / (2 * values_per_point) + 1));
  for (std::uint64_t i = 0; i < header.points; ++i) {
    const auto values = nextRowFields(lines, i, header.points, "points");
    if (values.size() != values_per_point) {
      lines.fail("point line has " + std::to_string(values.size()) + " values, expected " +
                 std::to_string(values_per_point));
    }
    const std::string_view x = values[column[header.x]];
    const std::string_view y = values[column[header.y]];
    const std::string_view z = values[column[header.z]];
    if (isNanToken(x) || isNanToken(y) || isNanToken(z)) continue;  // PCL's "no return"
    scan.points.emplace_back(parseCoordinate(lines, x, header.fields[header.x].size == 4),
                             parseCoordinate(lines, y, header.fields[header.y].size == 4),
                             parseCoordinate(lines, z, header.fields[header.z].size == 4));
    if (header.label) {
      const std::int64_t label = lines.parseInt(values[column[*header.label]]);
      if (label < 0 && header.fields[*header.label].type == 'U') {
        lines.fail("negative value for unsigned label");
      }
      scan.labels.push_back(checkedLabel(label, [&] { return lineWhere(lines); }));
    }
  }
  while (lines.next()) {
    if (!lines.fields().empty()) {
      lines.fail("more point lines than POINTS " + std::to_string(header.points));
    }
  }
}

}  // namespace

Scan readPcd(const std::filesystem::path& path) {
  const std::string source = path.string();
  InMemoryFile file(path);
  const std::string& bytes = file.bytes();
  TextLines lines(file.stream(), source);
  const Header header = parsePcdHeader(lines);

  Scan scan;
  scan.pose = header.viewpoint;
  scan.from_image = header.rows > 1;
  const std::size_t body_start = file.offset();
  switch (header.encoding) {
    case Encoding::Ascii: readAscii(header, lines, bytes.size() - body_start, scan); break;
    case Encoding::Binary: readBinary(header, bytes, body_start, source, scan); break;
    case Encoding::BinaryCompressed: readBinaryCompressed(header, bytes, body_start, source, scan); break;
  }
  return scan;
}

void writePcd(const std::filesystem::path& path, const Scan& scan, PcdEncoding encoding) {
  requireLabelPerPoint(path, scan);
  const bool with_labels = !scan.labels.empty();
  // Unsigned labels as PCL's PointXYZL has them, unless a label is negative.
  bool signed_labels = false;
  for (const std::int32_t label : scan.labels) signed_labels |= label < 0;
  const Encoding format = encoding == PcdEncoding::Ascii    ? Encoding::Ascii
                          : encoding == PcdEncoding::Binary ? Encoding::Binary
                                                            : Encoding::BinaryCompressed;
  std::string out = makePcdHeader(scan, with_labels, signed_labels, format);
  const std::size_t count = scan.size();
  const std::size_t point_bytes = with_labels ? 16 : 12;

  if (format == Encoding::Ascii) {
    out.reserve(out.size() + count * (with_labels ? 48 : 40));
    for (std::size_t i = 0; i < count; ++i) {
      appendFloatXyz(out, scan.points[i]);
      if (with_labels) {
        out += ' ';
        if (signed_labels) appendNumber(out, scan.labels[i]);
        else appendNumber(out, static_cast<std::uint32_t>(scan.labels[i]));
      }
      out += '\n';
    }
  } else if (format == Encoding::Binary) {
    const std::size_t header_bytes = out.size();
    out.resize(header_bytes + count * point_bytes);
    char* row = out.data() + header_bytes;
    for (std::size_t i = 0; i < count; ++i, row += point_bytes) {
      storeFloatXyz(row, scan.points[i]);
      if (with_labels) storeLittleEndian(row + 12, scan.labels[i]);
    }
  } else {
    if (count > std::numeric_limits<std::uint32_t>::max() / point_bytes) {
      throw Error(path.string() + ": " + std::to_string(count) +
                  " points are too many for binary_compressed (4 GiB limit); use binary");
    }
    // Field by field, as PCL lays it out before compressing.
    std::string unpacked(count * point_bytes, '\0');
    for (std::size_t i = 0; i < count; ++i) {
      const Point& point = scan.points[i];
      storeLittleEndian(unpacked.data() + 4 * i, static_cast<float>(point.x()));
      storeLittleEndian(unpacked.data() + 4 * (count + i), static_cast<float>(point.y()));
      storeLittleEndian(unpacked.data() + 4 * (2 * count + i), static_cast<float>(point.z()));
      if (with_labels) storeLittleEndian(unpacked.data() + 4 * (3 * count + i), scan.labels[i]);
    }
    // Incompressible input grows by one byte per 32 plus a little.
    std::string packed(unpacked.size() + unpacked.size() / 16 + 64, '\0');
    unsigned int packed_bytes = 0;
    if (!unpacked.empty()) {
      packed_bytes = lzf_compress(unpacked.data(), static_cast<unsigned int>(unpacked.size()),
                                  packed.data(), static_cast<unsigned int>(packed.size()));
      if (packed_bytes == 0) throw Error(path.string() + ": LZF compression failed");
    }
    char sizes[8];
    storeLittleEndian(sizes, static_cast<std::uint32_t>(packed_bytes));
    storeLittleEndian(sizes + 4, static_cast<std::uint32_t>(unpacked.size()));
    out.append(sizes, 8);
    out.append(packed.data(), packed_bytes);
  }
  writeWholeFile(path, out);
}

}  // namespace mlmap::io
