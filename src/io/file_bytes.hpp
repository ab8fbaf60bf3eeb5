// Internal helper for the scan formats: whole files in and out as bytes, an
// istream over bytes already in memory, and little-endian loads and stores that
// work on any host and any alignment (binary rows are packed, so unaligned).
#pragma once

#include <bit>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <istream>
#include <streambuf>
#include <string>
#include <string_view>
#include <utility>

#include "mlmap/io/regular_file.hpp"

namespace mlmap::io {

// The file's bytes; mlmap::Error "path: cannot open file" and the like.
std::string readWholeFile(const std::filesystem::path& path);

// requireRegularFile, then a binary stream; "path: cannot open for reading".
std::ifstream openForReading(const std::filesystem::path& path);

// writeAtomically with `bytes` as the whole content.
void writeWholeFile(const std::filesystem::path& path, const std::string& bytes);

// A file's bytes mapped read-only (no copy, and pages come from the page cache as they
// are read): a 40 MB map took 0.2 s to read() into a zeroed string on this VM. mlmap
// replaces files by rename (writeAtomically), never truncating one in place, which is
// what would fault a reader of a mapping.
class MappedFile {
 public:
  explicit MappedFile(const std::filesystem::path& path);  // mlmap::Error as readWholeFile
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  std::string_view bytes() const { return {data_, size_}; }

 private:
  const char* data_ = nullptr;
  std::size_t size_ = 0;
};

// A file read whole, with an istream over its bytes (no copy) for a text header
// followed by a binary body.
class InMemoryFile {
 public:
  explicit InMemoryFile(const std::filesystem::path& path);
  InMemoryFile(const InMemoryFile&) = delete;
  InMemoryFile& operator=(const InMemoryFile&) = delete;

  const std::string& bytes() const { return bytes_; }
  std::istream& stream() { return stream_; }
  // Bytes the stream has consumed: where the body starts once the header is read.
  std::size_t offset() const { return buffer_.offset(); }

 private:
  class Buffer : public std::streambuf {
   public:
    explicit Buffer(std::string& bytes) {
      setg(bytes.data(), bytes.data(), bytes.data() + bytes.size());
    }
    std::size_t offset() const { return static_cast<std::size_t>(gptr() - eback()); }
  };

  std::string bytes_;
  Buffer buffer_;
  std::istream stream_;
};

template <typename T>
T loadLittleEndian(const char* source) {
  T value;
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(&value, source, sizeof(T));
  } else {
    unsigned char reversed[sizeof(T)];
    for (std::size_t i = 0; i < sizeof(T); ++i) reversed[i] = source[sizeof(T) - 1 - i];
    std::memcpy(&value, reversed, sizeof(T));
  }
  return value;
}

template <typename T>
void storeLittleEndian(char* target, T value) {
  std::memcpy(target, &value, sizeof(T));
  if constexpr (std::endian::native != std::endian::little) {
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(target[i], target[sizeof(T) - 1 - i]);
  }
}

}  // namespace mlmap::io
