// Numeric options that read the whole text as a number and name the range they accept,
// in one style: "--cell-size: 'abc' is not a number", "--probability: 2 is not in (0, 1]".
// (CLI11's own checks print the limits of a double, 300 digits of DBL_MAX.)
#pragma once

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>

namespace mlmap::cli {

enum class Bound { Open, Closed };

inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

// The check: the text is one finite number (an integer when `integer`), within the bounds.
inline CLI::Validator numberIn(double low, Bound low_bound, double high = kUnbounded, Bound high_bound = Bound::Closed,
                               bool integer = false) {
  std::ostringstream range;
  range << (low_bound == Bound::Open ? "(" : "[") << low << ", ";
  if (std::isinf(high)) range << "∞)";
  else range << high << (high_bound == Bound::Open ? ")" : "]");
  const std::string range_text = range.str();
  return CLI::Validator(
      [=](const std::string& text) -> std::string {
        errno = 0;
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(value)) {
          return "'" + text + "' is not a number";
        }
        if (integer && value != std::floor(value)) return "'" + text + "' is not a whole number";
        const bool above = low_bound == Bound::Open ? value > low : value >= low;
        const bool below = high_bound == Bound::Open ? value < high : value <= high;
        if (!above || !below) return text + " is not in " + range_text;
        return "";
      },
      range_text);
}

// add_option with numberIn's check, for a double or an integer.
template <class T>
CLI::Option* addNumber(CLI::App* command, const std::string& name, T& value, const std::string& help, double low,
                       Bound low_bound, double high = kUnbounded, Bound high_bound = Bound::Closed) {
  if constexpr (std::is_integral_v<T>) {
    high = std::min(high, static_cast<double>(std::numeric_limits<T>::max()));
  }
  return command->add_option(name, value, help)
      ->check(numberIn(low, low_bound, high, high_bound, std::is_integral_v<T>));
}

}  // namespace mlmap::cli
