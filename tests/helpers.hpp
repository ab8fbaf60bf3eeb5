// Shared test helpers: temporary directories, file fixtures, the shared data folder,
// random scans, and the messages of the errors readers throw.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "mlmap/error.hpp"
#include "mlmap/scan.hpp"

namespace mlmap::test {

// A fresh directory under the system temp dir, removed when the object dies.
class TempDir {
 public:
  TempDir() {
    std::random_device device;
    path_ = std::filesystem::temp_directory_path() /
            ("mlmap-test-" + std::to_string(device()) + std::to_string(device()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

inline void writeText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

inline std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline std::filesystem::path sourceDir() { return MLMAP_SOURCE_DIR; }

// ../shared/data beside the checkout, when present (a user's clone has none).
inline std::optional<std::filesystem::path> sharedDataDir() {
  const auto path = sourceDir().parent_path() / "shared" / "data";
  if (std::filesystem::is_directory(path)) return path;
  return std::nullopt;
}

// Debian's liboctomap-dev example data (every machine with the package has it).
inline std::filesystem::path octomapExampleDir() {
  return "/usr/share/doc/liboctomap-dev/examples/data";
}

inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The message of the mlmap::Error that `call` throws; the test case fails (naming
// `context`) when it throws none.
template <typename Call>
std::string errorOf(Call&& call, const std::string& context = "") {
  try {
    call();
  } catch (const mlmap::Error& error) {
    return error.what();
  }
  FAIL("no mlmap::Error" << context);
  return {};
}

// Writes `bytes` to `path`, then the message of the mlmap::Error that `read(path)`
// throws; the test case fails when it throws none.
template <typename Read>
std::string errorReading(const std::filesystem::path& path, const std::string& bytes,
                         Read&& read) {
  writeText(path, bytes);
  return errorOf([&] { read(path); }, " reading " + path.filename().string() + " (" +
                                          std::to_string(bytes.size()) + " bytes)");
}

// Little-endian byte builder for hand-made binary bodies (the tests run on
// little-endian hosts, as the readers' users do).
template <typename T>
void put(std::string& bytes, T value) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  bytes.append(raw, sizeof(T));
}

struct LabelRange {
  std::int32_t min = 0, max = 0;
};

// `count` points uniform in [-extent, extent)³ from `seed`, each followed by a
// label from `labels` when given; identity pose.
inline Scan randomScan(std::size_t count, unsigned seed, double extent,
                       std::optional<LabelRange> labels = std::nullopt) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> coordinate(-extent, extent);
  std::uniform_int_distribution<std::int32_t> label(labels ? labels->min : 0,
                                                    labels ? labels->max : 0);
  Scan scan;
  for (std::size_t i = 0; i < count; ++i) {
    scan.points.emplace_back(coordinate(generator), coordinate(generator), coordinate(generator));
    if (labels) scan.labels.push_back(label(generator));
  }
  return scan;
}

// Per-point plane labels against the truth: of the points with a patch (label > 0),
// how many there are, and how many lie on the true plane most of their patch's points
// lie on (all of them when every patch holds one surface only).
struct LabelAgreement {
  std::size_t labelled = 0;
  std::size_t on_majority = 0;
  std::size_t misplaced() const { return labelled - on_majority; }
};

// Patch -> true plane -> points, over the points with a patch (label > 0).
using TruthByPatch = std::map<std::int32_t, std::map<std::int32_t, std::size_t>>;

inline TruthByPatch truthByPatch(const std::vector<std::int32_t>& predicted, const std::vector<std::int32_t>& truth) {
  REQUIRE(predicted.size() == truth.size());
  TruthByPatch counts;
  for (std::size_t k = 0; k < predicted.size(); ++k)
    if (predicted[k] > 0) ++counts[predicted[k]][truth[k]];
  return counts;
}

// The true plane most of one patch's points lie on.
inline std::int32_t majorityTruth(const std::map<std::int32_t, std::size_t>& by_truth) {
  return std::max_element(by_truth.begin(), by_truth.end(),
                          [](const auto& a, const auto& b) { return a.second < b.second; })->first;
}

inline LabelAgreement labelAgreement(const std::vector<std::int32_t>& predicted, const std::vector<std::int32_t>& truth) {
  LabelAgreement agreement;
  for (const auto& [patch, by_truth] : truthByPatch(predicted, truth)) {
    std::size_t best = 0;
    for (const auto& [plane, count] : by_truth) {
      best = std::max(best, count);
      agreement.labelled += count;
    }
    agreement.on_majority += best;
  }
  return agreement;
}

// Largest |read - written| / |written| over the points, which must match in number.
inline double maxRelativeError(const Scan& read, const Scan& written) {
  REQUIRE(read.size() == written.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < read.size(); ++i) {
    worst = std::max(worst, (read.points[i] - written.points[i]).norm() / written.points[i].norm());
  }
  return worst;
}

// Same number of points, each within `tolerance` (m) of its counterpart.
inline void checkSamePoints(const Scan& a, const Scan& b, double tolerance) {
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    CAPTURE(i);
    CHECK((a.points[i] - b.points[i]).norm() < tolerance);
  }
}

// Reads 300 damaged copies of `good` from `path` with `read` (every third one
// truncated, the others with four random bytes overwritten, from `seed`); every
// copy that reads must have no labels or one per point. Returns how many copies
// threw mlmap::Error.
template <typename Read>
int readCorruptedCopies(const std::string& good, const std::filesystem::path& path,
                        unsigned seed, Read&& read) {
  std::mt19937 generator(seed);
  int failures = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::string bytes = good;
    std::uniform_int_distribution<std::size_t> position(0, bytes.size() - 1);
    if (trial % 3 == 0) {
      bytes.resize(position(generator));
    } else {
      for (int k = 0; k < 4; ++k) bytes[position(generator)] = static_cast<char>(generator());
    }
    writeText(path, bytes);
    try {
      const Scan scan = read(path);
      CHECK((scan.labels.empty() || scan.labels.size() == scan.points.size()));
    } catch (const mlmap::Error&) {
      ++failures;
    }
  }
  return failures;
}

}  // namespace mlmap::test
