#include "mlmap/io/regular_file.hpp"

#include <system_error>

#include "mlmap/error.hpp"

namespace mlmap::io {

void requireRegularFile(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) throw Error(path.string() + ": no such file");
  refuseNonRegularFile(path);
}

void refuseNonRegularFile(const std::filesystem::path& path) {
  std::error_code error;
  if (std::filesystem::exists(path, error) && !std::filesystem::is_regular_file(path, error)) {
    throw Error(path.string() + ": not a regular file");
  }
}

}  // namespace mlmap::io
