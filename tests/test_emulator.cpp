// The emulator and the driver through the CLI: mlmap emulate in a child process,
// mlmap scan against its pseudo-terminals with a raw log, mlmap replay of that log.
#include <doctest/doctest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <sstream>
#include <thread>

#include "helpers.hpp"

extern char** environ;

namespace {

const char* const kBox = R"({
  "name": "box",
  "scan_pattern": {"mount_height": 0.6},
  "poses": [{"x": 2.0, "y": 1.5, "yaw_deg": 10}],
  "surfaces": [
    {"type": "rectangle", "name": "floor", "class": "floor", "min": [0, 0, 0], "max": [5, 4, 0]},
    {"type": "rectangle", "name": "ceiling", "class": "ceiling", "min": [0, 0, 2.5], "max": [5, 4, 2.5]},
    {"type": "rectangle", "name": "west", "class": "wall", "min": [0, 0, 0], "max": [0, 4, 2.5]},
    {"type": "rectangle", "name": "east", "class": "wall", "min": [5, 0, 0], "max": [5, 4, 2.5]},
    {"type": "rectangle", "name": "south", "class": "wall", "min": [0, 0, 0], "max": [5, 0, 2.5]},
    {"type": "rectangle", "name": "north", "class": "wall", "min": [0, 4, 0], "max": [5, 4, 2.5]}
  ]
})";

int run(const std::string& arguments, const mlmap::test::TempDir& dir) {
  const std::string command = std::string(MLMAP_CLI_PATH) + " " + arguments + " >" +
                              (dir / "stdout.txt").string() + " 2>" + (dir / "stderr.txt").string();
  return WEXITSTATUS(std::system(command.c_str()));
}

// `mlmap emulate` in a child process, with the device names it prints.
struct EmulateProcess {
  pid_t child = 0;
  std::string laser, ptu, output;
  EmulateProcess(const mlmap::test::TempDir& dir, const std::string& arguments) {
    output = (dir / "emulate.txt").string();
    const std::string shell = std::string("exec ") + MLMAP_CLI_PATH + " emulate " + (dir / "box.json").string() +
                              " " + arguments + " >" + output + " 2>&1";
    const char* argv[] = {"/bin/sh", "-c", shell.c_str(), nullptr};
    REQUIRE(posix_spawn(&child, "/bin/sh", nullptr, nullptr, const_cast<char* const*>(argv), environ) == 0);
    for (int i = 0; i < 300 && ptu.empty(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      std::istringstream lines(mlmap::test::readText(output));
      std::string key, value;
      while (lines >> key >> value) {
        if (key == "laser:") laser = value;
        if (key == "ptu:") ptu = value;
      }
    }
  }
  void stop() {
    if (child <= 0) return;
    ::kill(child, SIGINT);
    int status = 0;
    ::waitpid(child, &status, 0);
    child = 0;
  }
  ~EmulateProcess() { stop(); }
};

}  // namespace

TEST_CASE("CLI emulate --tcp: two scans in a row against one emulator") {
  mlmap::test::TempDir dir;
  mlmap::test::writeText(dir / "box.json", kBox);
  EmulateProcess emulate(dir, "--tcp --time-scale 4 --duration 30");
  REQUIRE_FALSE(emulate.ptu.empty());
  REQUIRE(emulate.laser.rfind("tcp:127.0.0.1:", 0) == 0);
  const std::string scans = (dir / "scans").string();
  for (int scan = 0; scan < 2; ++scan) {
    CAPTURE(scan);
    const int scanned = run("scan -q --laser " + emulate.laser + " --ptu " + emulate.ptu + " -o " + scans +
                                " --tilt-start -10 --tilt-end 10 --rho 2 --cluster 8 --pose 2 1.5 10",
                            dir);
    CHECK(scanned == 0);
    CAPTURE(mlmap::test::readText(dir / "stderr.txt"));
  }
  emulate.stop();
  CHECK(std::filesystem::exists(dir / "scans" / "scan_000.pcd"));
  CHECK(std::filesystem::exists(dir / "scans" / "scan_001.pcd"));
}

TEST_CASE("CLI emulate + scan + replay: a scan, its log, the same scan again") {
  mlmap::test::TempDir dir;
  mlmap::test::writeText(dir / "box.json", kBox);
  EmulateProcess emulate(dir, "--time-scale 4 --duration 20");
  const std::string& laser = emulate.laser;
  const std::string& ptu = emulate.ptu;
  const std::string emulate_out = emulate.output;
  REQUIRE_FALSE(ptu.empty());
  const std::string scans = (dir / "scans").string();
  const std::string log = (dir / "sweep.rawlog").string();
  const int scanned = run("scan -q --laser " + laser + " --ptu " + ptu + " -o " + scans + " --log " + log +
                              " --tilt-start -20 --tilt-end 20 --rho 2 --cluster 4 --pose 2 1.5 10",
                          dir);
  emulate.stop();
  REQUIRE(scanned == 0);
  CHECK(mlmap::test::contains(mlmap::test::readText(dir / "stdout.txt"), "scan_000.pcd"));
  CHECK(mlmap::test::contains(mlmap::test::readText(emulate_out), "laser scans sent"));
  REQUIRE(run("replay " + log + " -o " + (dir / "replayed").string(), dir) == 0);
  const std::string original = mlmap::test::readText(dir / "scans" / "scan_000.pcd");
  CHECK(original.size() > 1000);
  CHECK(original == mlmap::test::readText(dir / "replayed" / "scan_000.pcd"));

  // Bad input: one line on stderr, non-zero exit, nothing written.
  CHECK(run("scan --laser " + (dir / "missing").string() + " --ptu /dev/null -o " + (dir / "none").string(), dir) == 1);
  const std::string message = mlmap::test::readText(dir / "stderr.txt");
  CHECK(mlmap::test::contains(message, "missing: open"));
  CHECK(std::count(message.begin(), message.end(), '\n') == 1);
  CHECK_FALSE(std::filesystem::exists(dir / "none"));
  CHECK(run("replay " + (dir / "box.json").string() + " -o " + (dir / "none").string(), dir) == 1);
  CHECK(mlmap::test::contains(mlmap::test::readText(dir / "stderr.txt"), "not an mlmap raw log"));
  CHECK(run("emulate --help", dir) == 0);
  CHECK(mlmap::test::contains(mlmap::test::readText(dir / "stdout.txt"), "--fault-disconnect"));
}
