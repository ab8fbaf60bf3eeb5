#include "text_lines.hpp"

#include <charconv>
#include <cmath>

#include "mlmap/error.hpp"

namespace mlmap::io {

TextLines::TextLines(std::istream& in, std::string source_name)
    : in_(in), source_name_(std::move(source_name)) {}

bool TextLines::next() {
  if (!std::getline(in_, line_)) return false;
  ++line_number_;
  if (!line_.empty() && line_.back() == '\r') line_.pop_back();
  return true;
}

void TextLines::fail(const std::string& what) const {
  throw Error(source_name_ + ":" + std::to_string(line_number_) + ": " + what);
}

std::vector<std::string_view> TextLines::fields(bool hash_comments) const {
  std::vector<std::string_view> result;
  std::string_view rest = line_;
  if (hash_comments) {
    if (const auto hash = rest.find('#'); hash != std::string_view::npos) rest = rest.substr(0, hash);
  }
  std::size_t position = 0;
  while (position < rest.size()) {
    while (position < rest.size() && (rest[position] == ' ' || rest[position] == '\t' ||
                                      rest[position] == ',' || rest[position] == '\v' ||
                                      rest[position] == '\f')) {
      ++position;
    }
    const std::size_t start = position;
    while (position < rest.size() && rest[position] != ' ' && rest[position] != '\t' &&
           rest[position] != ',' && rest[position] != '\v' && rest[position] != '\f') {
      ++position;
    }
    if (position > start) result.push_back(rest.substr(start, position - start));
  }
  return result;
}

double TextLines::parseDouble(std::string_view field) const {
  double value = 0.0;
  const char* first = field.data();
  if (!field.empty() && field.front() == '+') ++first;
  const auto [end, error] = std::from_chars(first, field.data() + field.size(), value);
  if (error != std::errc() || end != field.data() + field.size()) {
    fail("expected a number, found '" + std::string(field.substr(0, 40)) + "'");
  }
  if (!std::isfinite(value)) fail("value is not finite: '" + std::string(field.substr(0, 40)) + "'");
  return value;
}

std::int64_t TextLines::parseInt(std::string_view field) const {
  std::int64_t value = 0;
  const char* first = field.data();
  if (!field.empty() && field.front() == '+') ++first;
  const auto [end, error] = std::from_chars(first, field.data() + field.size(), value);
  if (error != std::errc() || end != field.data() + field.size()) {
    fail("expected an integer, found '" + std::string(field.substr(0, 40)) + "'");
  }
  return value;
}

}  // namespace mlmap::io
