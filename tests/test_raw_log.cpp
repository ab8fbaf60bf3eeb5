// Raw logs: file round trip, hostile files, replay transports.
#include <doctest/doctest.h>

#include "helpers.hpp"
#include "mlmap/driver/raw_log.hpp"

using namespace mlmap::driver;

TEST_CASE("Raw log: save and load keep every byte and time exactly") {
  mlmap::test::TempDir dir;
  RawLog log;
  log.metadata = R"({"rho_deg": 1})";
  log.add({'L', 'w', 12.000000123456789, "MD0000108001000\n"});
  log.add({'L', 'r', 12.5, std::string("\0\n\r binary \xff", 13)});
  log.add({'P', 't', 13.25, ""});
  log.save(dir / "a.rawlog");
  const RawLog loaded = RawLog::load(dir / "a.rawlog");
  CHECK(loaded.metadata == log.metadata);
  REQUIRE(loaded.records().size() == 3);
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK(loaded.records()[i].device == log.records()[i].device);
    CHECK(loaded.records()[i].direction == log.records()[i].direction);
    CHECK(loaded.records()[i].host_s == log.records()[i].host_s);  // exact (hex float)
    CHECK(loaded.records()[i].bytes == log.records()[i].bytes);
  }
}

TEST_CASE("Raw log: malformed files are rejected with file and byte") {
  mlmap::test::TempDir dir;
  auto error = [&](const std::string& bytes) {
    return mlmap::test::errorReading(dir / "bad.rawlog", bytes, [](const auto& path) { RawLog::load(path); });
  };
  CHECK(mlmap::test::contains(error("hello"), "bad magic"));
  CHECK(mlmap::test::contains(error("mlmap-rawlog 1\nmeta 99\n{}\n"), "truncated"));
  CHECK(mlmap::test::contains(error("mlmap-rawlog 1\nmeta 2\n{}\nX w 0x1p+0 1\na\n"), "bad record header"));
  CHECK(mlmap::test::contains(error("mlmap-rawlog 1\nmeta 2\n{}\nL w nope 1\na\n"), "bad host time"));
  CHECK(mlmap::test::contains(error("mlmap-rawlog 1\nmeta 2\n{}\nL w 0x1p+0 -1\na\n"), "bad byte count"));
  CHECK(mlmap::test::contains(error("mlmap-rawlog 1\nmeta 2\n{}\nL w 0x1p+0 999999999\na\n"), "too large"));
  CHECK(mlmap::test::contains(error("mlmap-rawlog 1\nmeta 2\n{}\nL t 0x1p+0 1\na\n"), "timeout record"));
  CHECK(mlmap::test::contains(error("mlmap-rawlog 1\nmeta 2\n{}\nL w 0x1p+0 1\nab"), "newline"));
  mlmap::test::writeText(dir / "ok.rawlog", "mlmap-rawlog 1\nmeta 2\n{}\nL w 0x1p+0 1\na\n");
  CHECK(RawLog::load(dir / "ok.rawlog").records().at(0).host_s == 1.0);
  // 300 damaged copies of a good log: each either loads or throws mlmap::Error.
  RawLog log;
  log.metadata = "{}";
  for (int i = 0; i < 20; ++i) log.add({i % 2 ? 'L' : 'P', i % 3 ? 'r' : 'w', i * 0.5, std::string(i, 'x')});
  log.save(dir / "good.rawlog");
  const std::string good = mlmap::test::readText(dir / "good.rawlog");
  const int failures = mlmap::test::readCorruptedCopies(good, dir / "damaged.rawlog", 7, [](const auto& path) {
    RawLog::load(path);
    return mlmap::Scan{};
  });
  CHECK(failures > 50);
}

TEST_CASE("Raw log: replay returns the recorded reads and times, and notices divergence") {
  RawLog log;
  log.add({'L', 'w', 1.0, "VV\n"});
  log.add({'P', 'w', 1.5, "PP "});
  log.add({'L', 'r', 2.0, "VV\n00P\n"});
  log.add({'L', 't', 3.0, ""});
  ReplayTransport laser(log, 'L', "laser (replay)");
  laser.write("VV\n");
  CHECK(laser.now() == 1.0);
  char buffer[4];
  CHECK(laser.read(buffer, 4, std::chrono::milliseconds(0)) == 4);  // split over two reads
  CHECK(std::string(buffer, 4) == "VV\n0");
  CHECK(laser.read(buffer, 4, std::chrono::milliseconds(0)) == 3);
  CHECK(laser.now() == 2.0);
  CHECK(laser.read(buffer, 4, std::chrono::milliseconds(0)) == 0);  // the recorded timeout
  CHECK(mlmap::test::contains(mlmap::test::errorOf([&] { laser.read(buffer, 4, std::chrono::milliseconds(0)); }),
                              "the log ends"));
  ReplayTransport ptu(log, 'P', "ptu (replay)");
  CHECK(mlmap::test::contains(mlmap::test::errorOf([&] { ptu.write("TP "); }), "replay diverged"));
}
