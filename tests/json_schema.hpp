// A small JSON Schema checker for the subset our schemas use (type, const, enum,
// required, properties, additionalProperties, items, minItems/maxItems, minimum,
// exclusiveMinimum, $ref to #/$defs/...). Returns the first violation, with its path.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace mlmap::test {

class JsonSchema {
 public:
  explicit JsonSchema(nlohmann::json schema) : root_(std::move(schema)) {}

  std::optional<std::string> check(const nlohmann::json& value) const { return check(root_, value, "$"); }

 private:
  std::optional<std::string> check(const nlohmann::json& schema, const nlohmann::json& value,
                                   const std::string& path) const {
    if (schema.contains("$ref")) {
      const std::string ref = schema["$ref"];
      const std::string prefix = "#/$defs/";
      if (ref.rfind(prefix, 0) != 0) return path + ": unsupported $ref " + ref;
      return check(root_["$defs"][ref.substr(prefix.size())], value, path);
    }
    if (schema.contains("const") && value != schema["const"]) return path + ": must be " + schema["const"].dump();
    if (schema.contains("enum")) {
      bool found = false;
      for (const auto& option : schema["enum"]) found = found || option == value;
      if (!found) return path + ": " + value.dump() + " is not one of " + schema["enum"].dump();
    }
    if (schema.contains("type")) {
      const std::string type = schema["type"];
      const bool ok = (type == "object" && value.is_object()) || (type == "array" && value.is_array()) ||
                      (type == "string" && value.is_string()) ||
                      (type == "integer" && value.is_number_integer()) ||
                      (type == "number" && value.is_number()) || (type == "boolean" && value.is_boolean());
      if (!ok) return path + ": expected " + type + ", found " + value.type_name();
    }
    if (value.is_number()) {
      if (schema.contains("minimum") && value.get<double>() < schema["minimum"].get<double>()) {
        return path + ": below the minimum";
      }
      if (schema.contains("exclusiveMinimum") && value.get<double>() <= schema["exclusiveMinimum"].get<double>()) {
        return path + ": not above the exclusive minimum";
      }
    }
    if (value.is_array()) {
      if (schema.contains("minItems") && value.size() < schema["minItems"].get<std::size_t>()) return path + ": too few items";
      if (schema.contains("maxItems") && value.size() > schema["maxItems"].get<std::size_t>()) return path + ": too many items";
      if (schema.contains("items")) {
        for (std::size_t k = 0; k < value.size(); ++k) {
          if (auto error = check(schema["items"], value[k], path + "[" + std::to_string(k) + "]")) return error;
        }
      }
    }
    if (value.is_object()) {
      if (schema.contains("required")) {
        for (const auto& key : schema["required"]) {
          if (!value.contains(key.get<std::string>())) return path + ": missing " + key.get<std::string>();
        }
      }
      for (const auto& [key, item] : value.items()) {
        if (schema.contains("properties") && schema["properties"].contains(key)) {
          if (auto error = check(schema["properties"][key], item, path + "." + key)) return error;
        } else if (schema.contains("additionalProperties")) {
          const auto& additional = schema["additionalProperties"];
          if (additional.is_boolean() && !additional.get<bool>()) return path + ": unexpected property " + key;
          if (additional.is_object()) {
            if (auto error = check(additional, item, path + "." + key)) return error;
          }
        }
      }
    }
    return std::nullopt;
  }

  nlohmann::json root_;
};

}  // namespace mlmap::test
