#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "helpers.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/xyz.hpp"

using mlmap::Error;
using mlmap::Scan;
using mlmap::io::readXyz;
using mlmap::io::writeXyz;
using mlmap::test::contains;
using mlmap::test::TempDir;
using mlmap::test::writeText;

namespace {

// The message of the Error that reading `text` as an XYZ file throws.
std::string xyzError(const TempDir& dir, const std::string& text) {
  return mlmap::test::errorReading(dir / "bad.xyz", text, readXyz);
}

}  // namespace

TEST_CASE("xyz: reads points, skips comments and blank lines") {
  TempDir dir;
  writeText(dir / "a.xyz", "# header\n\n1 2 3\n  -4.5\t5e-1,+6   # trailing comment\r\n\n7 8 9");
  const Scan scan = readXyz(dir / "a.xyz");
  REQUIRE(scan.size() == 3);
  CHECK(scan.points[0] == mlmap::Point(1, 2, 3));
  CHECK(scan.points[1] == mlmap::Point(-4.5, 0.5, 6));
  CHECK(scan.points[2] == mlmap::Point(7, 8, 9));
  CHECK(scan.labels.empty());
  CHECK(scan.pose.isApprox(mlmap::Pose::Identity()));
}

TEST_CASE("xyz: integer 4th column on every line becomes labels") {
  TempDir dir;
  writeText(dir / "a.xyz", "1 2 3 7\n# comment\n4 5 6 -2 0.25 ignored\n");
  const Scan scan = readXyz(dir / "a.xyz");
  REQUIRE(scan.size() == 2);
  REQUIRE(scan.labels.size() == 2);
  CHECK(scan.labels[0] == 7);
  CHECK(scan.labels[1] == -2);
}

TEST_CASE("xyz: a non-integer 4th column (intensity) leaves the file unlabelled") {
  TempDir dir;
  writeText(dir / "a.xyz", "1 2 3 1\n4 5 6 0.53\n7 8 9 2\n");
  const Scan scan = readXyz(dir / "a.xyz");
  CHECK(scan.size() == 3);
  CHECK(scan.labels.empty());
  CHECK(scan.points[1] == mlmap::Point(4, 5, 6));
}

TEST_CASE("xyz: bad input names file and line") {
  TempDir dir;
  SUBCASE("short line") {
    const std::string message = xyzError(dir, "1 2 3\n\n4 5\n");
    CHECK(contains(message, "bad.xyz:3"));
    CHECK(contains(message, "3 fields"));
  }
  SUBCASE("non-numeric field") {
    const std::string message = xyzError(dir, "1 2 3\n1 2 abc\n");
    CHECK(contains(message, "bad.xyz:2"));
    CHECK(contains(message, "'abc'"));
  }
  SUBCASE("number followed by garbage") {
    CHECK(contains(xyzError(dir, "1 2 3x\n"), "bad.xyz:1"));
  }
  SUBCASE("double sign") {
    CHECK(contains(xyzError(dir, "1 2 +-3\n"), "bad.xyz:1"));
  }
  SUBCASE("nan") {
    const std::string message = xyzError(dir, "1 2 3\n4 nan 6\n");
    CHECK(contains(message, "bad.xyz:2"));
    CHECK(contains(message, "not finite"));
  }
  SUBCASE("inf") { CHECK(contains(xyzError(dir, "# c\n-inf 2 3\n"), "bad.xyz:2")); }
  SUBCASE("overflowing number") {
    CHECK(contains(xyzError(dir, "1e999 2 3\n"), "bad.xyz:1"));
  }
  SUBCASE("4th column on some lines only") {
    const std::string message = xyzError(dir, "1 2 3 1\n4 5 6 2\n7 8 9\n");
    CHECK(contains(message, "bad.xyz:3"));
  }
  SUBCASE("4th column appearing late") {
    CHECK(contains(xyzError(dir, "1 2 3\n4 5 6 2\n"), "bad.xyz:2"));
  }
  SUBCASE("non-numeric 4th column") {
    CHECK(contains(xyzError(dir, "1 2 3 red\n"), "bad.xyz:1"));
  }
  SUBCASE("empty file") {
    const std::string message = xyzError(dir, "");
    CHECK(contains(message, "bad.xyz:1"));
    CHECK(contains(message, "no points"));
  }
  SUBCASE("comments only") {
    CHECK(contains(xyzError(dir, "# a\n# b\n\n"), "bad.xyz:3: no points"));
  }
  SUBCASE("binary garbage") {
    CHECK(contains(xyzError(dir, std::string("\x01\x02\x00\xff", 4)), "bad.xyz:1"));
  }
}

TEST_CASE("xyz: missing file") {
  TempDir dir;
  CHECK_THROWS_WITH_AS(readXyz(dir / "nope.xyz"), doctest::Contains("nope.xyz: no such file"),
                       Error);
}

TEST_CASE("xyz: write then read round-trips to 1 um, labels exactly") {
  TempDir dir;
  Scan scan = mlmap::test::randomScan(1000, 7, 50.0);
  for (int i = 0; i < 1000; ++i) scan.labels.push_back(i % 5 - 2);
  scan.points.emplace_back(0.0, -0.0, 1e-9);  // rounds to zero
  scan.labels.push_back(std::numeric_limits<std::int32_t>::min());
  scan.points.emplace_back(1e15, -2.5e13, 123.0);  // beyond the fixed-point range
  scan.labels.push_back(std::numeric_limits<std::int32_t>::max());
  writeXyz(dir / "out.xyz", scan);
  const Scan back = readXyz(dir / "out.xyz");
  REQUIRE(back.size() == scan.size());
  CHECK(back.labels == scan.labels);
  for (std::size_t i = 0; i < scan.size(); ++i) {
    INFO("point " << i);
    CHECK((back.points[i] - scan.points[i]).cwiseAbs().maxCoeff() <= 5e-7);
  }
  CHECK(back.points[scan.size() - 1] == scan.points[scan.size() - 1]);

  SUBCASE("unlabelled scans are written with three columns") {
    scan.labels.clear();
    writeXyz(dir / "plain.xyz", scan);
    CHECK(readXyz(dir / "plain.xyz").labels.empty());
    const std::string text = mlmap::test::readText(dir / "plain.xyz");
    const std::string first_line = text.substr(0, text.find('\n'));
    CHECK(std::count(first_line.begin(), first_line.end(), ' ') == 2);
  }
}

TEST_CASE("xyz: writer output is compact and exact for micrometre values") {
  TempDir dir;
  Scan scan;
  scan.points = {{1.5, -0.25, 0.0}, {-3.000001, 2.0, 10.123456}};
  writeXyz(dir / "out.xyz", scan);
  CHECK(mlmap::test::readText(dir / "out.xyz") == "1.5 -0.25 0\n-3.000001 2 10.123456\n");
}

TEST_CASE("xyz: writer refuses bad scans and leaves no file") {
  TempDir dir;
  Scan scan;
  scan.points = {{1, 2, 3}, {std::nan(""), 0, 0}};
  CHECK_THROWS_WITH_AS(writeXyz(dir / "out.xyz", scan), doctest::Contains("point 1"), Error);
  CHECK_FALSE(std::filesystem::exists(dir / "out.xyz"));
  scan.points[1] = {0, 0, 0};
  scan.labels = {1};
  CHECK_THROWS_AS(writeXyz(dir / "out.xyz", scan), Error);
  CHECK(std::filesystem::is_empty(dir.path()));
}
