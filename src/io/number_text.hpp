// Internal helper for the text writers: numbers appended as the shortest text
// that reads back as the same value (std::to_chars, no locale).
#pragma once

#include <charconv>
#include <string>

namespace mlmap::io {

template <typename T>
void appendNumber(std::string& out, T value) {
  char buffer[40];  // enough for any double, float or integer
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}

}  // namespace mlmap::io
