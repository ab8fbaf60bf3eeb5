// Shared by the fuzz targets. The file readers take paths, so each input is written to
// one file per target in a private directory (on /dev/shm when there is one: no disk in
// the loop) and read back through the real entry point. The device clients read a
// Transport, so ReplyTransport serves the input as the device's bytes and swallows what
// the client writes; when the bytes run out every read times out at once, which the
// clients report as mlmap::Error like any silent device.
//
// The only exception a reader may throw is mlmap::Error: anything else (bad_alloc,
// length_error, out_of_range) escapes LLVMFuzzerTestOneInput and libFuzzer reports it.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "mlmap/driver/transport.hpp"
#include "mlmap/error.hpp"

namespace mlmap::fuzz {

class InputFiles {
 public:
  InputFiles() {
    const std::filesystem::path shm = "/dev/shm";
    const std::filesystem::path base =
        std::filesystem::is_directory(shm) ? shm : std::filesystem::temp_directory_path();
    directory_ = base / ("mlmap-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(directory_);
  }
  ~InputFiles() {
    std::error_code ignored;
    std::filesystem::remove_all(directory_, ignored);
  }
  InputFiles(const InputFiles&) = delete;
  InputFiles& operator=(const InputFiles&) = delete;

  // `bytes` as the whole content of the file `name` in the directory.
  std::filesystem::path write(const std::string& name, std::string_view bytes) const {
    const std::filesystem::path path = directory_ / name;
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path;
  }

 private:
  std::filesystem::path directory_;
};

inline const InputFiles& inputFiles() {
  static const InputFiles files;
  return files;
}

inline std::string_view asText(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Runs `read`; a clean refusal (mlmap::Error) is as good as a result.
template <typename Read>
void refusedOrRead(Read&& read) {
  try {
    read();
  } catch (const mlmap::Error&) {
  }
}

class ReplyTransport : public driver::Transport {
 public:
  explicit ReplyTransport(std::string_view bytes) : bytes_(bytes) {}
  void write(std::string_view) override {}
  std::size_t read(char* buffer, std::size_t capacity, std::chrono::milliseconds) override {
    // Small chunks, so frames and lines straddle reads as they do on a serial line.
    const std::size_t count = std::min({capacity, bytes_.size(), std::size_t{61}});
    std::memcpy(buffer, bytes_.data(), count);
    bytes_.remove_prefix(count);
    return count;
  }
  const std::string& name() const override { return name_; }

 private:
  std::string_view bytes_;
  std::string name_ = "fuzz device";
};

}  // namespace mlmap::fuzz
