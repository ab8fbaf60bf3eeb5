#include "output_check.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "mlmap/error.hpp"

namespace mlmap::cli {

void checkWritable(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (fs::is_directory(path, error)) throw Error(path + ": is a directory; give a file name to write");
  const fs::path parent = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
  if (!fs::is_directory(parent, error)) throw Error(path + ": no directory " + parent.string() + " to write it in");
  if (::access(parent.c_str(), W_OK) != 0) {
    throw Error(path + ": cannot write in " + parent.string() + " (" + std::strerror(errno) + ")");
  }
}

}  // namespace mlmap::cli
