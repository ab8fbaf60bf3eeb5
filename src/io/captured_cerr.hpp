// OctoMap reports on stderr, through std::cerr and through fprintf ("Reading
// octree type OcTree", "Writing 300 points to binary file...", warnings on bad
// input). The library never prints, so its calls run with both captured, and what
// it said can go into an error message. Not for concurrent use: it swaps the
// process's standard error while alive.
#pragma once

#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>

namespace mlmap::io {

class CapturedCerr {
 public:
  CapturedCerr() : previous_(std::cerr.rdbuf(captured_.rdbuf())) {
    std::fflush(stderr);
    sink_ = std::tmpfile();
    saved_fd_ = sink_ ? ::dup(STDERR_FILENO) : -1;
    if (saved_fd_ >= 0) ::dup2(::fileno(sink_), STDERR_FILENO);
  }
  ~CapturedCerr() {
    restore();
    if (sink_) std::fclose(sink_);
    std::cerr.rdbuf(previous_);
  }
  CapturedCerr(const CapturedCerr&) = delete;
  CapturedCerr& operator=(const CapturedCerr&) = delete;

  // What was written so far, on one line.
  std::string text() {
    std::string result = captured_.str();
    if (sink_) {
      std::fflush(stderr);
      std::rewind(sink_);
      char buffer[512];
      std::size_t count = 0;
      while ((count = std::fread(buffer, 1, sizeof(buffer), sink_)) > 0) result.append(buffer, count);
    }
    for (char& c : result) {
      if (c == '\n') c = ' ';
    }
    return result;
  }

 private:
  void restore() {
    if (saved_fd_ < 0) return;
    std::fflush(stderr);
    ::dup2(saved_fd_, STDERR_FILENO);
    ::close(saved_fd_);
    saved_fd_ = -1;
  }

  std::ostringstream captured_;
  std::streambuf* previous_;
  std::FILE* sink_ = nullptr;
  int saved_fd_ = -1;
};

}  // namespace mlmap::io
