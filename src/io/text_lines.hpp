// Internal helper for the text formats (XYZ, TUM, 3DTK, ASCII PLY/PCD bodies):
// reads lines while counting them, splits fields and parses numbers strictly, so
// every error names "file:line".
#pragma once

#include <cstdint>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

namespace mlmap::io {

class TextLines {
 public:
  TextLines(std::istream& in, std::string source_name);

  // Reads the next line (without '\n' or a trailing '\r'); false at end of input.
  bool next();
  std::string_view line() const { return line_; }
  std::size_t lineNumber() const { return line_number_; }
  const std::string& sourceName() const { return source_name_; }

  // Throws mlmap::Error "source:line: what".
  [[noreturn]] void fail(const std::string& what) const;

  // Whitespace-separated fields of the current line; a '#' starts a comment when
  // `hash_comments` is set.
  std::vector<std::string_view> fields(bool hash_comments = false) const;

  // Strict parsing: the whole field must be a finite number, else fail() naming it.
  double parseDouble(std::string_view field) const;
  std::int64_t parseInt(std::string_view field) const;

 private:
  std::istream& in_;
  std::string source_name_;
  std::string line_;
  std::size_t line_number_ = 0;
};

}  // namespace mlmap::io
