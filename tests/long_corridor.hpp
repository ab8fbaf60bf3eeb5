// The stress benchmark's long corridor (bench/icp_stress.py, "long-corridor") as a scene, for the
// tests that replay its pairs and sequences.
#pragma once

#include <array>
#include <cstdio>
#include <string>

namespace mlmap::test {

// 30 × 2.2 × 2.8 m, five door niches 1 m wide and 0.15 m deep on alternating sides, the first on
// y = 0, at x = `niches`; scanned as the benchmark scans (270° field, 0.5° beams, 1° lines) from
// `poses` (a JSON array of {x, y, yaw_deg}) with `range_sigma` of noise and the simulator's `seed`.
// The numbers are written to round-trip exactly: the scene is the one the benchmark drew.
inline std::string longCorridorJson(const std::string& poses, const std::array<double, 5>& niches, double range_sigma,
                                    int seed) {
  const auto exact = [](double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", value);
    return std::string(text);
  };
  std::string json = R"({
    "scan_pattern": {"field_of_view_deg": 270, "angular_step_deg": 0.5, "tilt_start_deg": -46,
                     "tilt_end_deg": 46, "tilt_step_deg": 1.0, "min_range": 0.023, "max_range": 30,
                     "mount_height": 1.2, "range_sigma": )" +
                     exact(range_sigma) + R"(, "seed": )" + std::to_string(seed) + R"(},
    "poses": )" + poses + R"(,
    "surfaces": [
      {"type": "rectangle", "class": "floor", "min": [0, 0, 0], "max": [30, 2.2, 0]},
      {"type": "rectangle", "class": "ceiling", "min": [0, 0, 2.8], "max": [30, 2.2, 2.8]},
      {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [0, 2.2, 2.8], "facing": "+x"},
      {"type": "rectangle", "class": "wall", "min": [30, 0, 0], "max": [30, 2.2, 2.8], "facing": "-x"},
      {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [30, 0, 2.8], "facing": "+y"},
      {"type": "rectangle", "class": "wall", "min": [0, 2.2, 0], "max": [30, 2.2, 2.8], "facing": "-y"})";
  for (std::size_t k = 0; k < niches.size(); ++k) {
    const bool low = k % 2 == 0;  // in the wall y = 0, else in y = 2.2
    json += R"(,
      {"type": "box", "class": "other", "min": [)" + exact(niches[k]) + (low ? ", -0.15, 0" : ", 2.2, 0") +
            "], \"max\": [" + exact(niches[k] + 1.0) + (low ? ", 0, 2.1" : ", 2.35, 2.1") +
            "], \"omit\": [" + (low ? "\"y+\"" : "\"y-\"") + "]}";
  }
  return json + "\n    ]\n  }";
}

}  // namespace mlmap::test
