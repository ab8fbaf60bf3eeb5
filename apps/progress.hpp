// Progress on stderr for long work: a redrawn bar on a terminal, a line per tenth
// otherwise (so logs stay readable). Silent when disabled (--quiet).
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace mlmap::cli {

class Progress {
 public:
  Progress(std::string label, std::size_t total, bool enabled);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void update(std::size_t done, const std::string& detail = "");
  void finish(const std::string& detail = "");

 private:
  void draw(std::size_t done, const std::string& detail);

  std::string label_;
  std::size_t total_;
  bool enabled_;
  bool terminal_;
  bool finished_ = false;
  int last_tenth_ = -1;
  std::string last_detail_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace mlmap::cli
