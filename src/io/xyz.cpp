// XYZ text scans. Reading is the hot path when a large cloud is loaded, so the
// file is read whole and parsed with std::from_chars in one pass (no iostream
// extraction per number, no per-line allocation); the strictness is TextLines'
// (whole field must be a finite number, '+' allowed, separators space, tab, comma).
//
// Label rule: the 4th column is a label only when EVERY point line has one and
// every one is a decimal integer that fits int32. A 4th column that is some other
// number (an intensity such as 0.53, or 1.0) makes the file unlabelled; the
// column is then ignored, like every column after the 4th. A file where some
// point lines have a 4th column and others do not is rejected at the first line
// that breaks the pattern, since columns cannot be told apart any more.
//
// The writer prints 6 decimals (1 µm) with trailing zeros dropped: half the size
// of exact shortest-round-trip output for float-derived data, and 2M points
// format in a fraction of a second.
#include "mlmap/io/xyz.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include "file_bytes.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/atomic_file.hpp"

namespace mlmap::io {
namespace {

bool isSeparator(char c) {
  return c == ' ' || c == '\t' || c == ',' || c == '\v' || c == '\f' || c == '\r';
}

std::string readText(const std::filesystem::path& path) {
  std::ifstream in = openForReading(path);
  std::error_code error;
  const auto size = std::filesystem::file_size(path, error);
  if (error) throw Error(path.string() + ": cannot read size (" + error.message() + ")");
  std::string data(static_cast<std::size_t>(size), '\0');
  in.read(data.data(), static_cast<std::streamsize>(data.size()));
  if (static_cast<std::size_t>(in.gcount()) != data.size()) {
    throw Error(path.string() + ": read failed after " + std::to_string(in.gcount()) + " bytes");
  }
  return data;
}

bool endsField(const char* position, const char* end) {
  return position == end || isSeparator(*position) || *position == '\n' || *position == '#';
}

const char* skipSeparators(const char* position, const char* end) {
  while (position < end && isSeparator(*position)) ++position;
  return position;
}

// Parses numbers straight out of the file buffer: std::from_chars reads each
// field once, and the character after it must end the field.
class Parser {
 public:
  Parser(const std::string& source, const std::string& data)
      : source_(source), position_(data.data()), end_(data.data() + data.size()) {}

  bool atEnd() const { return position_ >= end_; }
  std::size_t lineNumber() const { return line_number_; }

  // Skips separators; true when a field follows on this line.
  bool fieldFollows() {
    position_ = skipSeparators(position_, end_);
    return position_ < end_ && *position_ != '\n' && *position_ != '#';
  }

  // Moves past the rest of the current line (comment, ignored columns, newline).
  void nextLine() {
    const void* newline = std::memchr(position_, '\n', static_cast<std::size_t>(end_ - position_));
    position_ = newline ? static_cast<const char*>(newline) + 1 : end_;
    ++line_number_;
  }

  double parseDouble() {
    double value = 0.0;
    if (!parseNumber(value)) fail("expected a number, found '" + currentField() + "'");
    if (!std::isfinite(value)) fail("value is not finite: '" + currentField() + "'");
    position_ = number_end_;
    return value;
  }

  // A decimal integer that fits int32 (consumed), or nothing (position unchanged).
  std::optional<std::int32_t> parseLabel() {
    std::int64_t value = 0;
    if (!parseNumber(value) || value < std::numeric_limits<std::int32_t>::min() ||
        value > std::numeric_limits<std::int32_t>::max()) {
      return std::nullopt;
    }
    position_ = number_end_;
    return static_cast<std::int32_t>(value);
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(source_ + ":" + std::to_string(line_number_) + ": " + what);
  }

 private:
  // The same strictness as TextLines: an optional single '+', then a number that
  // fills the whole field.
  template <typename Number>
  bool parseNumber(Number& value) {
    const char* first = position_;
    if (first < end_ && *first == '+') {
      ++first;
      if (first < end_ && (*first == '-' || *first == '+')) return false;
    }
    const auto [end, error] = std::from_chars(first, end_, value);
    number_end_ = end;
    return error == std::errc() && end != first && endsField(end, end_);
  }

  std::string currentField() const {
    const char* last = position_;
    while (!endsField(last, end_) && last - position_ < 40) ++last;
    return {position_, last};
  }

  const std::string& source_;
  const char* position_;
  const char* end_;
  const char* number_end_ = nullptr;
  std::size_t line_number_ = 1;
};

// Coordinates with 6 decimals (1 µm, far below any laser's noise), trailing
// zeros dropped; magnitudes beyond 9e12 m fall back to the shortest exact form.
char* formatCoordinate(char* out, double value) {
  constexpr double kMaxFixed = 9e12;
  if (!(std::abs(value) < kMaxFixed)) return std::to_chars(out, out + 32, value).ptr;
  std::int64_t micro = std::llround(value * 1e6);
  if (micro < 0) {
    *out++ = '-';
    micro = -micro;
  }
  out = std::to_chars(out, out + 24, micro / 1000000).ptr;
  std::int64_t fraction = micro % 1000000;
  if (fraction != 0) {
    char digits[6];
    for (int i = 5; i >= 0; --i, fraction /= 10) digits[i] = static_cast<char>('0' + fraction % 10);
    int length = 6;
    while (digits[length - 1] == '0') --length;
    *out++ = '.';
    std::memcpy(out, digits, static_cast<std::size_t>(length));
    out += length;
  }
  return out;
}

}  // namespace

Scan readXyz(const std::filesystem::path& path) {
  const std::string source = path.string();
  const std::string data = readText(path);

  Scan scan;
  scan.points.reserve(data.size() / 32);
  bool labels_possible = true;
  bool has_fourth_column = false;
  std::size_t first_point_line = 0;

  Parser parser(source, data);
  for (; !parser.atEnd(); parser.nextLine()) {
    if (!parser.fieldFollows()) continue;  // blank or comment-only line
    double xyz[3];
    for (int axis = 0; axis < 3; ++axis) {
      if (axis > 0 && !parser.fieldFollows()) {
        parser.fail("expected at least 3 fields (x y z), found " + std::to_string(axis));
      }
      xyz[axis] = parser.parseDouble();
    }
    scan.points.emplace_back(xyz[0], xyz[1], xyz[2]);

    const bool fourth = parser.fieldFollows();
    if (first_point_line == 0) {
      first_point_line = parser.lineNumber();
      has_fourth_column = fourth;
    } else if (fourth != has_fourth_column) {
      parser.fail(std::string(fourth ? "unexpected 4th column" : "missing the 4th column") +
                  " (line " + std::to_string(first_point_line) + (fourth ? " has 3" : " has 4") +
                  "); every point line must have the same columns");
    }
    if (!fourth) continue;
    const auto label = parser.parseLabel();
    if (!label) parser.parseDouble();  // not a label, but it still has to be a number
    if (!labels_possible) continue;
    if (label) {
      scan.labels.push_back(*label);
    } else {
      labels_possible = false;
      scan.labels.clear();
      scan.labels.shrink_to_fit();
    }
  }

  if (scan.points.empty()) {
    const std::size_t last_line = std::max<std::size_t>(parser.lineNumber() - 1, 1);
    throw Error(source + ":" + std::to_string(last_line) + ": no points in file" +
                (data.empty() ? " (empty file)" : ""));
  }
  return scan;
}

void writeXyz(const std::filesystem::path& path, const Scan& scan) {
  const bool labelled = !scan.labels.empty();
  if (labelled && scan.labels.size() != scan.points.size()) {
    throw Error(path.string() + ": scan has " + std::to_string(scan.labels.size()) +
                " labels for " + std::to_string(scan.points.size()) + " points");
  }
  for (std::size_t index = 0; index < scan.points.size(); ++index) {
    if (!scan.points[index].allFinite()) {
      throw Error(path.string() + ": point " + std::to_string(index) + " is not finite");
    }
  }
  writeAtomically(path, [&](std::ostream& out) {
    constexpr std::size_t kFlushBytes = 1 << 20;
    constexpr std::size_t kMaxLineBytes = 4 * 32;
    std::string buffer(kFlushBytes + kMaxLineBytes, '\0');
    char* const begin = buffer.data();
    char* cursor = begin;
    for (std::size_t index = 0; index < scan.points.size(); ++index) {
      const Point& point = scan.points[index];
      cursor = formatCoordinate(cursor, point.x());
      *cursor++ = ' ';
      cursor = formatCoordinate(cursor, point.y());
      *cursor++ = ' ';
      cursor = formatCoordinate(cursor, point.z());
      if (labelled) {
        *cursor++ = ' ';
        cursor = std::to_chars(cursor, cursor + 16, scan.labels[index]).ptr;
      }
      *cursor++ = '\n';
      if (static_cast<std::size_t>(cursor - begin) >= kFlushBytes) {
        out.write(begin, cursor - begin);
        cursor = begin;
      }
    }
    out.write(begin, cursor - begin);
  });
}

}  // namespace mlmap::io
