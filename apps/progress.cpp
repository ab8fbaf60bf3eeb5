#include "progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace mlmap::cli {

Progress::Progress(std::string label, std::size_t total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled),
      terminal_(::isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() {
  if (!finished_) finish();
}

void Progress::update(std::size_t done, const std::string& detail) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const int tenth = total_ == 0 ? 10 : static_cast<int>(10 * done / total_);
  if (terminal_) {
    if (now - last_draw_ < std::chrono::milliseconds(100) && done < total_) return;
  } else if (tenth == last_tenth_) {
    return;
  }
  last_tenth_ = tenth;
  last_draw_ = now;
  last_detail_ = detail;
  draw(done, detail);
}

void Progress::finish(const std::string& detail) {
  if (finished_) return;
  finished_ = true;
  if (!enabled_) return;
  // A log already has its last line when the final update reached the total.
  if (!terminal_ && last_tenth_ == 10 && detail == last_detail_) return;
  draw(total_, detail);
  if (terminal_) std::fputc('\n', stderr);
}

void Progress::draw(std::size_t done, const std::string& detail) {
  const double fraction = total_ == 0 ? 1.0 : static_cast<double>(done) / static_cast<double>(total_);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  constexpr int kWidth = 24;
  const int filled = static_cast<int>(fraction * kWidth + 0.5);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kWidth, '.');
  std::fprintf(stderr, "%s%-10s [%s] %zu/%zu %5.1fs %s%s", terminal_ ? "\r" : "", label_.c_str(),
               bar.c_str(), done, total_, seconds, detail.c_str(), terminal_ ? "\033[K" : "\n");
  std::fflush(stderr);
}

}  // namespace mlmap::cli
