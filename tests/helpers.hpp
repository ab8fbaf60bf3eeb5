// Shared test helpers: temporary directories, file fixtures, the shared data folder.
#pragma once

#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <string>

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

}  // namespace mlmap::test
