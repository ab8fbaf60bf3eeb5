#include "file_bytes.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mlmap/error.hpp"
#include "mlmap/io/atomic_file.hpp"

namespace mlmap::io {

std::string readWholeFile(const std::filesystem::path& path) {
  // A device or a pipe has no size to read up to: /dev/zero read as empty (a dashboard page
  // of nothing was written without a word).
  requireRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open file");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) throw Error(path.string() + ": cannot determine file size");
  in.seekg(0, std::ios::beg);
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (!in.read(bytes.data(), size)) throw Error(path.string() + ": read failed");
  return bytes;
}

MappedFile::MappedFile(const std::filesystem::path& path) {
  requireRegularFile(path);
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw Error(path.string() + ": cannot open file");
  struct stat info {};
  if (::fstat(fd, &info) != 0 || info.st_size < 0) {
    ::close(fd);
    throw Error(path.string() + ": cannot determine file size");
  }
  size_ = static_cast<std::size_t>(info.st_size);
  if (size_ > 0) {
    void* mapped = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (mapped == MAP_FAILED) {
      ::close(fd);
      throw Error(path.string() + ": read failed (cannot map the file)");
    }
    data_ = static_cast<const char*>(mapped);
  }
  ::close(fd);  // the mapping keeps the file
}

MappedFile::~MappedFile() {
  if (data_ != nullptr) ::munmap(const_cast<char*>(data_), size_);
}

std::ifstream openForReading(const std::filesystem::path& path) {
  requireRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open for reading");
  return in;
}

void writeWholeFile(const std::filesystem::path& path, const std::string& bytes) {
  writeAtomically(path, [&](std::ostream& out) {
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  });
}

InMemoryFile::InMemoryFile(const std::filesystem::path& path)
    : bytes_(readWholeFile(path)), buffer_(bytes_), stream_(&buffer_) {}

}  // namespace mlmap::io
