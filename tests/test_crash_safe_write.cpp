// Crash-safe writes (io/atomic_file.hpp): a process killed with SIGKILL in the middle of
// writing a large map leaves the previous map untouched, and the half-written temporary
// file it leaves behind is neither named like a map nor accepted by the map reader.
#include <doctest/doctest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <optional>

#include "helpers.hpp"
#include "mlmap/io/atomic_file.hpp"
#include "mlmap/io/map_file.hpp"
#include "mlmap/io/scan_file.hpp"
#include "mlmap/map/map.hpp"

namespace fs = std::filesystem;
using namespace mlmap;

namespace {

// side² cells of 5 cm, each with a floor block and one at `shelf_height`.
Map gridMap(int side, double shelf_height) {
  MapConfig config;
  config.cell_size = 0.05;
  config.with_octree = false;
  Map map(config);
  Scan scan;
  scan.points.reserve(2 * static_cast<std::size_t>(side) * static_cast<std::size_t>(side));
  for (int i = 0; i < side; ++i) {
    for (int j = 0; j < side; ++j) {
      const double x = (i + 0.5) * config.cell_size, y = (j + 0.5) * config.cell_size;
      scan.points.emplace_back(x, y, 0.0);
      scan.points.emplace_back(x, y, shelf_height);
    }
  }
  map.insertIntoBlocks(scan);
  return map;
}

// Every file in `dir` other than `keep`.
std::optional<fs::path> otherFile(const fs::path& dir, const fs::path& keep) {
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(dir, error)) {
    if (entry.path() != keep) return entry.path();
  }
  return std::nullopt;
}

struct KillResult {
  bool during_write = false;           // killed while its temporary file was being filled
  std::optional<fs::path> temporary;   // what it left behind
};

// Forks a child that writes `map` to `path` and kills it (SIGKILL) as soon as its
// temporary file holds some but not all of the `full_size` bytes. The child may win
// the race on a fast machine; then the write completed and nothing was killed.
KillResult killWhileWriting(const fs::path& path, const Map& map, std::uintmax_t full_size) {
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    try {
      io::writeMap(path, map);
    } catch (...) {
    }
    ::_exit(0);
  }
  KillResult result;
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    if (const auto temporary = otherFile(path.parent_path(), path)) {
      std::error_code error;
      const auto size = fs::file_size(*temporary, error);
      if (!error && size > 0 && size < full_size) {
        ::kill(child, SIGKILL);
        result.during_write = true;
        break;
      }
    }
    if (::waitpid(child, &status, WNOHANG) == child) return result;  // finished first
  }
  if (!result.during_write) ::kill(child, SIGKILL);  // deadline: never stuck
  REQUIRE(::waitpid(child, &status, 0) == child);
  CHECK(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGKILL);
  result.temporary = otherFile(path.parent_path(), path);
  return result;
}

}  // namespace

TEST_CASE("Crash-safe writes: SIGKILL while a large map is written keeps the old map") {
  test::TempDir dir, scratch;
  const fs::path path = dir / "site.mlmap";
  const Map old_map = gridMap(30, 1.0);
  // 1000² cells, 2 million blocks: a 44 MB file, tens of milliseconds of writing.
  const Map large_map = gridMap(1000, 2.0);
  io::writeMap(scratch / "large.mlmap", large_map);
  const auto full_size = fs::file_size(scratch / "large.mlmap");
  REQUIRE(full_size > 40'000'000);

  bool interrupted = false;
  for (int attempt = 0; attempt < 5 && !interrupted; ++attempt) {
    io::writeMap(path, old_map);
    const std::string old_bytes = test::readText(path);
    const KillResult killed = killWhileWriting(path, large_map, full_size);
    if (!killed.during_write) {
      // The writer won the race: the new map is there, whole.
      CHECK(io::readMap(path).blocks().blockCount() == large_map.blocks().blockCount());
      continue;
    }
    interrupted = true;
    // The previous map, byte for byte, and it reads back as it was.
    CHECK(test::readText(path) == old_bytes);
    const Map read = io::readMap(path);
    CHECK(read.blocks().cellCount() == old_map.blocks().cellCount());
    CHECK(read.blocks().blockCount() == old_map.blocks().blockCount());
    // The half-written temporary file: hidden, not a .mlmap name, refused by the readers.
    REQUIRE(killed.temporary);
    const fs::path& temporary = *killed.temporary;
    MESSAGE("killed with " << fs::file_size(temporary) << " of " << full_size
                           << " bytes written to " << temporary.filename().string());
    CHECK(temporary.filename().string().front() == '.');
    CHECK(temporary.extension() != ".mlmap");
    CHECK(fs::file_size(temporary) < full_size);
    CHECK_THROWS_AS(io::readMap(temporary), Error);
    CHECK_THROWS_AS(io::readScans(temporary), Error);
  }
  CHECK_MESSAGE(interrupted, "the writer finished every time before it could be killed");
}

TEST_CASE("Crash-safe writes: SIGINT or SIGTERM during a write removes its temporary file") {
  for (const int signal_number : {SIGINT, SIGTERM}) {
    test::TempDir dir;
    const fs::path path = dir / "out.xyz";
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0) {
      io::removeTemporaryFilesOnSignal();
      try {
        // The signal arrives with the temporary file created and half written.
        io::writeAtomically(path, [&](std::ostream& out) {
          out << "0 0 0\n";
          out.flush();
          ::raise(signal_number);
          out << "1 1 1\n";
        });
      } catch (...) {
      }
      ::_exit(0);  // not reached: the signal ends the child
    }
    int status = 0;
    REQUIRE(::waitpid(child, &status, 0) == child);
    CHECK(WIFSIGNALED(status));
    CHECK(WTERMSIG(status) == signal_number);
    CHECK_FALSE(otherFile(dir.path(), path).has_value());  // no .out.xyz.PID.0.tmp
    CHECK_FALSE(fs::exists(path));
  }
}
