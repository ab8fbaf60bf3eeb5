#include "mlmap/io/atomic_file.hpp"

#include <fcntl.h>
#include <limits.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
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

// The temporary files of the writes in progress, for the signal handler: plain
// characters and lock-free states, the only things a handler may touch.
enum SlotState : int { kFree, kFilling, kPublished };
struct InProgress {
  std::atomic<int> state{kFree};
  char path[PATH_MAX] = {};
};
std::array<InProgress, 16> in_progress;

// Marks `temporary` in progress; returns its slot, or nullptr when all are taken (then
// a signal leaves that one behind, as before).
InProgress* track(const std::filesystem::path& temporary) {
  const std::string& text = temporary.native();
  if (text.size() >= PATH_MAX) return nullptr;
  for (InProgress& slot : in_progress) {
    int expected = kFree;
    if (!slot.state.compare_exchange_strong(expected, kFilling)) continue;
    std::memcpy(slot.path, text.c_str(), text.size() + 1);
    slot.state.store(kPublished, std::memory_order_release);  // the handler reads whole paths only
    return &slot;
  }
  return nullptr;
}

void untrack(InProgress* slot) {
  if (slot != nullptr) slot->state.store(kFree, std::memory_order_release);
}

extern "C" void removeTemporaryAndDie(int signal_number) {
  for (InProgress& slot : in_progress) {
    if (slot.state.load(std::memory_order_acquire) == kPublished) ::unlink(slot.path);
  }
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
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
  InProgress* const slot = track(temporary);
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
    untrack(slot);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    untrack(slot);
    throw;
  }
}

void removeTemporaryFilesOnSignal() {
  struct sigaction action {};
  action.sa_handler = removeTemporaryAndDie;
  sigemptyset(&action.sa_mask);
  for (const int signal_number : {SIGINT, SIGTERM}) {
    struct sigaction previous {};
    // A signal the caller's parent ignores (nohup, a shell's background job) stays ignored.
    if (::sigaction(signal_number, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) continue;
    ::sigaction(signal_number, &action, nullptr);
  }
}

}  // namespace mlmap::io
