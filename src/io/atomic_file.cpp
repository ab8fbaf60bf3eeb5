#include "mlmap/io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>

#include "mlmap/error.hpp"

namespace mlmap::io {
namespace {

std::filesystem::path temporaryPathFor(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  // A name no reader mistakes for a map: hidden, and ending in .tmp.
  std::string name = "." + path.filename().string() + "." + std::to_string(::getpid()) + "." +
                     std::to_string(counter++) + ".tmp";
  return path.parent_path() / name;
}

void syncFile(const std::filesystem::path& path) {
  int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

void writeAtomically(const std::filesystem::path& path,
                     const std::function<void(std::ostream&)>& write) {
  const std::filesystem::path temporary = temporaryPathFor(path);
  try {
    {
      std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
      if (!out) {
        throw Error(path.string() + ": cannot create file (" + std::strerror(errno) + ")");
      }
      write(out);
      out.flush();
      if (!out) throw Error(path.string() + ": write failed (disk full?)");
    }
    syncFile(temporary);
    std::error_code error;
    std::filesystem::rename(temporary, path, error);
    if (error) throw Error(path.string() + ": cannot rename temporary file (" + error.message() + ")");
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw;
  }
}

}  // namespace mlmap::io
