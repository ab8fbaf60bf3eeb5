// The PCD header: read line by line (errors name the line) and checked as a whole;
// written for the points that follow it.
#include "pcd_header.hpp"

#include <algorithm>
#include <limits>
#include <string_view>

#include "mlmap/error.hpp"
#include "number_text.hpp"

namespace mlmap::io {
namespace {

[[noreturn]] void failAt(const std::string& source, std::size_t line, const std::string& what) {
  throw Error(source + ":" + std::to_string(line) + ": " + what);
}

std::uint64_t parseCount(const TextLines& lines, std::string_view field) {
  const std::int64_t value = lines.parseInt(field);
  if (value < 0) lines.fail("negative value " + std::string(field));
  return static_cast<std::uint64_t>(value);
}

}  // namespace

Header parsePcdHeader(TextLines& lines) {
  std::vector<std::string> names, types;
  std::vector<std::size_t> sizes, counts;
  std::optional<std::uint64_t> width, height, points;
  std::size_t fields_line = 0, sizes_line = 0, types_line = 0, counts_line = 0;
  std::size_t width_line = 0, points_line = 0;
  Header header;
  const auto once = [&](std::size_t& line_of_key, std::string_view key) {
    if (line_of_key != 0) lines.fail("duplicate " + std::string(key) + " line");
    line_of_key = lines.lineNumber();
  };
  std::size_t version_line = 0, height_line = 0, viewpoint_line = 0;

  while (true) {
    if (!lines.next()) lines.fail("file ends inside the PCD header (no DATA line)");
    const auto tokens = lines.fields(/*hash_comments=*/true);
    if (tokens.empty()) continue;
    const std::string_view key = tokens[0];
    const std::size_t values = tokens.size() - 1;
    if (key == "VERSION") {
      once(version_line, key);
      static const std::vector<std::string_view> known = {"0.7", ".7", "v0.7", "v.7", "0.6",
                                                          ".6",  "v.6", "0.5", ".5",  "v.5"};
      if (values != 1 || std::find(known.begin(), known.end(), tokens[1]) == known.end()) {
        lines.fail("unsupported PCD version (expected VERSION 0.7)");
      }
    } else if (key == "FIELDS" || key == "COLUMNS") {
      once(fields_line, key);
      if (values == 0) lines.fail("FIELDS names no field");
      for (std::size_t i = 1; i < tokens.size(); ++i) names.emplace_back(tokens[i]);
    } else if (key == "SIZE") {
      once(sizes_line, key);
      for (std::size_t i = 1; i < tokens.size(); ++i) {
        const std::uint64_t size = parseCount(lines, tokens[i]);
        if (size != 1 && size != 2 && size != 4 && size != 8) {
          lines.fail("SIZE must be 1, 2, 4 or 8, found " + std::string(tokens[i]));
        }
        sizes.push_back(size);
      }
    } else if (key == "TYPE") {
      once(types_line, key);
      for (std::size_t i = 1; i < tokens.size(); ++i) {
        if (tokens[i] != "F" && tokens[i] != "I" && tokens[i] != "U") {
          lines.fail("TYPE must be F, I or U, found '" + std::string(tokens[i]) + "'");
        }
        types.emplace_back(tokens[i]);
      }
    } else if (key == "COUNT") {
      once(counts_line, key);
      for (std::size_t i = 1; i < tokens.size(); ++i) {
        const std::uint64_t count = parseCount(lines, tokens[i]);
        // A point of more than a million values is not a point cloud.
        if (count == 0 || count > 1'000'000) lines.fail("COUNT out of range: " + std::string(tokens[i]));
        counts.push_back(count);
      }
    } else if (key == "WIDTH") {
      once(width_line, key);
      if (values != 1) lines.fail("expected 'WIDTH <n>'");
      width = parseCount(lines, tokens[1]);
    } else if (key == "HEIGHT") {
      once(height_line, key);
      if (values != 1) lines.fail("expected 'HEIGHT <n>'");
      height = parseCount(lines, tokens[1]);
    } else if (key == "VIEWPOINT") {
      once(viewpoint_line, key);
      if (values != 7) lines.fail("expected 'VIEWPOINT tx ty tz qw qx qy qz'");
      double v[7];
      for (int i = 0; i < 7; ++i) v[i] = lines.parseDouble(tokens[i + 1]);
      Eigen::Quaterniond rotation(v[3], v[4], v[5], v[6]);
      if (rotation.norm() < 1e-9) lines.fail("VIEWPOINT quaternion is zero");
      header.viewpoint = Pose::Identity();
      header.viewpoint.translate(Eigen::Vector3d(v[0], v[1], v[2]));
      header.viewpoint.rotate(rotation.normalized());
    } else if (key == "POINTS") {
      once(points_line, key);
      if (values != 1) lines.fail("expected 'POINTS <n>'");
      points = parseCount(lines, tokens[1]);
    } else if (key == "DATA") {
      if (values != 1) lines.fail("expected 'DATA ascii|binary|binary_compressed'");
      if (tokens[1] == "ascii") {
        header.encoding = Encoding::Ascii;
      } else if (tokens[1] == "binary") {
        header.encoding = Encoding::Binary;
      } else if (tokens[1] == "binary_compressed") {
        header.encoding = Encoding::BinaryCompressed;
      } else {
        lines.fail("unknown DATA encoding '" + std::string(tokens[1]) + "'");
      }
      break;
    } else {
      lines.fail("not a PCD header line: unknown keyword '" + std::string(key.substr(0, 40)) + "'");
    }
  }

  const std::string& source = lines.sourceName();
  if (fields_line == 0) lines.fail("PCD header has no FIELDS line");
  if (sizes_line == 0) lines.fail("PCD header has no SIZE line");
  if (types_line == 0) lines.fail("PCD header has no TYPE line");
  if (width_line == 0) lines.fail("PCD header has no WIDTH line");
  const auto same_length = [&](std::size_t length, std::size_t line, std::string_view key) {
    if (length != names.size()) {
      failAt(source, line, std::string(key) + " has " + std::to_string(length) +
                               " entries but FIELDS has " + std::to_string(names.size()));
    }
  };
  same_length(sizes.size(), sizes_line, "SIZE");
  same_length(types.size(), types_line, "TYPE");
  if (counts_line != 0) same_length(counts.size(), counts_line, "COUNT");
  if (counts_line == 0) counts.assign(names.size(), 1);

  // HEIGHT defaults to 1 and POINTS to WIDTH*HEIGHT, as in PCL's older headers.
  const std::uint64_t rows = height.value_or(1);
  if (rows != 0 && *width > std::numeric_limits<std::uint64_t>::max() / rows) {
    failAt(source, width_line, "WIDTH * HEIGHT overflows");
  }
  const std::uint64_t organized_points = *width * rows;
  if (points && *points != organized_points) {
    failAt(source, points_line, "POINTS " + std::to_string(*points) + " is not WIDTH * HEIGHT = " +
                                    std::to_string(organized_points));
  }
  header.points = organized_points;
  header.rows = rows;

  std::optional<std::size_t> x, y, z;
  for (std::size_t i = 0; i < names.size(); ++i) {
    Field field{names[i], sizes[i], types[i][0], counts[i], header.point_bytes};
    if (field.type == 'F' && field.size != 4 && field.size != 8) {
      failAt(source, sizes_line, "float field '" + field.name + "' must have SIZE 4 or 8");
    }
    header.point_bytes += field.size * field.count;
    std::optional<std::size_t>* coordinate = field.name == "x"   ? &x
                                             : field.name == "y" ? &y
                                             : field.name == "z" ? &z
                                                                 : nullptr;
    if (coordinate != nullptr && !*coordinate) {
      if (field.type != 'F' || field.count != 1) {
        failAt(source, types_line, "field '" + field.name + "' must be a float (F 4 or F 8) with COUNT 1");
      }
      *coordinate = i;
    }
    // Float or multi-valued labels are not ours to interpret: ignored.
    if (field.name == "label" && field.type != 'F' && field.count == 1 && !header.label) {
      header.label = i;
    }
    header.fields.push_back(std::move(field));
  }
  if (!x || !y || !z) failAt(source, fields_line, "PCD file has no x, y and z fields");
  header.x = *x;
  header.y = *y;
  header.z = *z;
  return header;
}

// ---------------------------------------------------------------- decoding

std::string makePcdHeader(const Scan& scan, bool with_labels, bool signed_labels, Encoding encoding) {
  std::string header = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n";
  header += with_labels ? "FIELDS x y z label\nSIZE 4 4 4 4\n" : "FIELDS x y z\nSIZE 4 4 4\n";
  header += with_labels ? (signed_labels ? "TYPE F F F I\nCOUNT 1 1 1 1\n" : "TYPE F F F U\nCOUNT 1 1 1 1\n")
                        : "TYPE F F F\nCOUNT 1 1 1\n";
  header += "WIDTH " + std::to_string(scan.size()) + "\nHEIGHT 1\nVIEWPOINT";
  const Eigen::Vector3d translation = scan.pose.translation();
  const Eigen::Quaterniond rotation = Eigen::Quaterniond(scan.pose.linear()).normalized();
  for (const double value : {translation.x(), translation.y(), translation.z(), rotation.w(),
                             rotation.x(), rotation.y(), rotation.z()}) {
    header += ' ';
    appendNumber(header, value);
  }
  header += "\nPOINTS " + std::to_string(scan.size()) + "\nDATA ";
  header += encoding == Encoding::Ascii    ? "ascii\n"
            : encoding == Encoding::Binary ? "binary\n"
                                           : "binary_compressed\n";
  return header;
}

}  // namespace mlmap::io
