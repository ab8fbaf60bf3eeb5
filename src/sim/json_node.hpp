// Internal to the scene loader: a JSON value with the path that led to it, so every
// error names the file and the element ("lab.json: surfaces[3].size: expected 3
// numbers"). Shared by scene.cpp (one file's elements) and scene_include.cpp.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "mlmap/error.hpp"

namespace mlmap::sim::detail {

// A JSON value with the path that led to it, for messages.
class JsonNode {
 public:
  JsonNode(const nlohmann::json& value, std::string path, const std::string& source)
      : value_(value), path_(std::move(path)), source_(source) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(source_ + ": " + (path_.empty() ? std::string("(top level)") : path_) + ": " +
                what);
  }

  const nlohmann::json& value() const { return value_; }
  const std::string& path() const { return path_; }
  const std::string& source() const { return source_; }

  bool has(const std::string& key) const { return value_.contains(key); }

  JsonNode operator[](const std::string& key) const {
    if (!value_.contains(key)) JsonNode(value_, join(key), source_).fail("missing");
    return JsonNode(value_.at(key), join(key), source_);
  }
  JsonNode operator[](std::size_t index) const {
    return JsonNode(value_.at(index), path_ + "[" + std::to_string(index) + "]", source_);
  }

  void expectObject() const {
    if (!value_.is_object()) fail("expected an object");
  }
  std::size_t arraySize() const {
    if (!value_.is_array()) fail("expected an array");
    return value_.size();
  }

  // Unknown keys are typos more often than not; keys starting with '_' are comments.
  void allowOnly(std::initializer_list<std::string_view> keys) const {
    expectObject();
    for (const auto& item : value_.items()) {
      const std::string& key = item.key();
      if (!key.empty() && key.front() == '_') continue;
      if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
        JsonNode(item.value(), join(key), source_).fail("unknown field");
      }
    }
  }

  double number() const {
    if (!value_.is_number()) fail("expected a number");
    const double result = value_.get<double>();
    if (!std::isfinite(result)) fail("expected a finite number");
    return result;
  }
  double positive() const {
    const double result = number();
    if (!(result > 0.0)) fail("must be positive");
    return result;
  }
  double nonNegative() const {
    const double result = number();
    if (result < 0.0) fail("must not be negative");
    return result;
  }
  std::int64_t integer() const {
    if (!value_.is_number_integer()) fail("expected an integer");
    return value_.get<std::int64_t>();
  }
  std::uint64_t unsignedInteger() const {
    if (!value_.is_number_unsigned()) fail("expected a non-negative integer");
    return value_.get<std::uint64_t>();
  }
  bool boolean() const {
    if (!value_.is_boolean()) fail("expected true or false");
    return value_.get<bool>();
  }
  std::string string() const {
    if (!value_.is_string()) fail("expected a string");
    return value_.get<std::string>();
  }
  std::vector<double> numbers(std::size_t count) const {
    if (!value_.is_array() || value_.size() != count) {
      fail("expected " + std::to_string(count) + " numbers");
    }
    std::vector<double> result;
    for (std::size_t i = 0; i < count; ++i) result.push_back((*this)[i].number());
    return result;
  }
  Eigen::Vector3d vector3() const {
    const auto v = numbers(3);
    return {v[0], v[1], v[2]};
  }
  Eigen::Vector2d vector2() const {
    const auto v = numbers(2);
    return {v[0], v[1]};
  }

  double numberOr(const std::string& key, double fallback) const {
    return has(key) ? (*this)[key].number() : fallback;
  }
  double positiveOr(const std::string& key, double fallback) const {
    return has(key) ? (*this)[key].positive() : fallback;
  }
  double nonNegativeOr(const std::string& key, double fallback) const {
    return has(key) ? (*this)[key].nonNegative() : fallback;
  }
  std::string stringOr(const std::string& key, const std::string& fallback) const {
    return has(key) ? (*this)[key].string() : fallback;
  }

 private:
  std::string join(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  const nlohmann::json& value_;
  std::string path_;
  const std::string& source_;
};

}  // namespace mlmap::sim::detail
