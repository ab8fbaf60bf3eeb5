// PLY reader and writer: round trips of both encodings, hand-made files with the
// layouts other tools write, and hostile input that must fail with file and line/byte.
#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include "helpers.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/ply.hpp"

using mlmap::Point;
using mlmap::Scan;
using mlmap::io::PlyEncoding;
using mlmap::io::readPly;
using mlmap::io::writePly;
using mlmap::test::contains;
using mlmap::test::errorOf;
using mlmap::test::LabelRange;
using mlmap::test::put;
using mlmap::test::TempDir;
using mlmap::test::writeText;

namespace {

Scan randomScan(std::size_t count, bool with_labels, unsigned seed) {
  const auto labels = with_labels ? std::optional(LabelRange{-5, 100000}) : std::nullopt;
  return mlmap::test::randomScan(count, seed, 50.0, labels);
}

}  // namespace

TEST_CASE("ply: round trip of both encodings, with and without labels") {
  TempDir dir;
  for (const PlyEncoding encoding : {PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian}) {
    for (const bool with_labels : {false, true}) {
      CAPTURE(static_cast<int>(encoding));
      CAPTURE(with_labels);
      const Scan written = randomScan(1000, with_labels, 7);
      const auto path = dir / "cloud.ply";
      writePly(path, written, encoding);
      const Scan read = readPly(path);
      // Written as float: each coordinate rounded to 24 bits (relative error 2^-24).
      CHECK(mlmap::test::maxRelativeError(read, written) < 1e-7);
      CHECK(read.labels == written.labels);
    }
  }
}

TEST_CASE("ply: an empty scan round-trips") {
  TempDir dir;
  for (const PlyEncoding encoding : {PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian}) {
    writePly(dir / "empty.ply", Scan{}, encoding);
    const Scan read = readPly(dir / "empty.ply");
    CHECK(read.size() == 0);
    CHECK(read.labels.empty());
  }
}

TEST_CASE("ply: writer rejects labels that do not match the points") {
  TempDir dir;
  Scan scan = randomScan(3, true, 1);
  scan.labels.pop_back();
  CHECK_THROWS_AS(writePly(dir / "x.ply", scan), mlmap::Error);
  CHECK_FALSE(std::filesystem::exists(dir / "x.ply"));
}

TEST_CASE("ply: ascii with a property between x and y, comments and a face element") {
  TempDir dir;
  writeText(dir / "a.ply",
            "ply\r\n"
            "format ascii 1.0\r\n"
            "comment made by hand\r\n"
            "obj_info nothing\r\n"
            "element vertex 3\r\n"
            "property float x\r\n"
            "property float intensity\r\n"
            "property float y\r\n"
            "property float z\r\n"
            "property uchar label\r\n"
            "element face 1\r\n"
            "property list uchar int vertex_indices\r\n"
            "end_header\r\n"
            "1 99 2 3 4\r\n"
            "-1.1 0 2.5 -3.5 0\r\n"
            "1e2 7 0 0 255\r\n"
            "3 0 1 2\r\n");
  const Scan scan = readPly(dir / "a.ply");
  REQUIRE(scan.size() == 3);
  CHECK(scan.points[0] == Point(1, 2, 3));
  CHECK(scan.points[1] == Point(-1.1F, 2.5, -3.5));  // float: rounded as a binary file would be
  CHECK(scan.points[2] == Point(100, 0, 0));
  CHECK(scan.labels == std::vector<std::int32_t>{4, 0, 255});
}

TEST_CASE("ply: ascii with a list element before the vertices and a float label") {
  TempDir dir;
  writeText(dir / "a.ply",
            "ply\nformat ascii 1.0\n"
            "element camera 2\nproperty list uchar float k\nproperty int id\n"
            "element vertex 2\nproperty double x\nproperty double y\nproperty double z\n"
            "property float label\nproperty list int int extra\n"
            "end_header\n"
            "3 1 2 3 0\n"
            "0 1\n"
            "0.1 0.25 0.5 1.5 2 9 9\n"
            "1 2 3 0.5 0\n");
  const Scan scan = readPly(dir / "a.ply");
  REQUIRE(scan.size() == 2);
  CHECK(scan.points[0] == Point(0.1, 0.25, 0.5));  // double: not rounded to float
  CHECK(scan.points[1] == Point(1, 2, 3));
  CHECK(scan.labels.empty());  // float labels are not read
}

TEST_CASE("ply: binary with double coordinates, odd-sized properties and lists before the vertices") {
  TempDir dir;
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\n"
      "element material 2\nproperty list uint8 int16 ids\nproperty ushort flag\n"
      "element vertex 2\n"
      "property float64 x\nproperty uchar intensity\nproperty float64 y\nproperty short ring\n"
      "property float64 z\nproperty ushort label\n"
      "element face 1\nproperty list uchar int vertex_indices\n"
      "end_header\n";
  // material 0: list of 3 int16 + flag; material 1: empty list + flag
  put<std::uint8_t>(bytes, 3);
  put<std::int16_t>(bytes, 1);
  put<std::int16_t>(bytes, 2);
  put<std::int16_t>(bytes, 3);
  put<std::uint16_t>(bytes, 7);
  put<std::uint8_t>(bytes, 0);
  put<std::uint16_t>(bytes, 8);
  const double coordinates[2][3] = {{0.1, -2.000000001, 1e6 + 0.25}, {-7.0, 8.5, 1e-9}};
  const std::uint16_t labels[2] = {65535, 3};
  for (int i = 0; i < 2; ++i) {
    put<double>(bytes, coordinates[i][0]);
    put<std::uint8_t>(bytes, 200);
    put<double>(bytes, coordinates[i][1]);
    put<std::int16_t>(bytes, -4);
    put<double>(bytes, coordinates[i][2]);
    put<std::uint16_t>(bytes, labels[i]);
  }
  put<std::uint8_t>(bytes, 3);
  for (int v : {0, 1, 0}) put<std::int32_t>(bytes, v);
  writeText(dir / "b.ply", bytes);

  const Scan scan = readPly(dir / "b.ply");
  REQUIRE(scan.size() == 2);
  for (int i = 0; i < 2; ++i) {
    // Doubles are kept exactly.
    CHECK(scan.points[i] == Point(coordinates[i][0], coordinates[i][1], coordinates[i][2]));
  }
  CHECK(scan.labels == std::vector<std::int32_t>{65535, 3});
}

TEST_CASE("ply: binary with a list property inside the vertex element") {
  TempDir dir;
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
      "property float x\nproperty list uchar float extra\nproperty float y\nproperty float z\n"
      "property int label\nend_header\n";
  for (int i = 0; i < 3; ++i) {
    put<float>(bytes, static_cast<float>(i));
    put<std::uint8_t>(bytes, static_cast<std::uint8_t>(i));  // i extra floats
    for (int k = 0; k < i; ++k) put<float>(bytes, 1234.0F);
    put<float>(bytes, 10.0F + static_cast<float>(i));
    put<float>(bytes, -0.5F);
    put<std::int32_t>(bytes, -i);
  }
  writeText(dir / "c.ply", bytes);
  const Scan scan = readPly(dir / "c.ply");
  REQUIRE(scan.size() == 3);
  for (int i = 0; i < 3; ++i) CHECK(scan.points[i] == Point(i, 10 + i, -0.5));
  CHECK(scan.labels == std::vector<std::int32_t>{0, -1, -2});
}

TEST_CASE("ply: bad headers fail naming file and line") {
  TempDir dir;
  const auto path = dir / "bad.ply";
  const auto failure = [&](const std::string& text) {
    return mlmap::test::errorReading(path, text, readPly);
  };
  const std::string vertex_xyz =
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n";

  std::string message = failure("plx\nformat ascii 1.0\n");
  CHECK_MESSAGE(contains(message, "bad.ply:1:"), message);

  message = failure("ply\nformat binary_big_endian 1.0\n" + vertex_xyz + "end_header\n");
  CHECK_MESSAGE(contains(message, "bad.ply:2:"), message);
  CHECK_MESSAGE(contains(message, "unsupported"), message);

  message = failure("ply\nformat utf8 1.0\n" + vertex_xyz + "end_header\n");
  CHECK_MESSAGE(contains(message, "bad.ply:2:"), message);

  message = failure("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                    "property float y\nend_header\n1 2\n");
  CHECK_MESSAGE(contains(message, "bad.ply:3:"), message);
  CHECK_MESSAGE(contains(message, "z"), message);

  message = failure("ply\nformat ascii 1.0\nelement vertex 1\nproperty int x\n"
                    "property float y\nproperty float z\nend_header\n1 2 3\n");
  CHECK_MESSAGE(contains(message, "bad.ply:3:"), message);

  message = failure("ply\nformat ascii 1.0\n" + vertex_xyz);
  CHECK_MESSAGE(contains(message, "end_header"), message);

  message = failure("ply\nformat ascii 1.0\nelement vertex 1\nproperty float32 x\n"
                    "property vec3 y\nend_header\n");
  CHECK_MESSAGE(contains(message, "bad.ply:5:"), message);

  message = failure("ply\nformat ascii 1.0\nelement vertex -3\nend_header\n");
  CHECK_MESSAGE(contains(message, "bad.ply:3:"), message);

  message = failure("ply\n" + vertex_xyz + "end_header\n1 2 3\n");
  CHECK_MESSAGE(contains(message, "format"), message);

  CHECK_THROWS_AS(readPly(dir / "missing.ply"), mlmap::Error);
}

TEST_CASE("ply: bad ascii bodies fail naming file and line") {
  TempDir dir;
  const auto path = dir / "bad.ply";
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty int label\nend_header\n";  // 8 lines
  const auto failure = [&](const std::string& body) {
    return mlmap::test::errorReading(path, header + body, readPly);
  };
  std::string message = failure("1 2 3 0\n4 nan 6 0\n7 8 9 0\n");
  CHECK_MESSAGE(contains(message, "bad.ply:10:"), message);

  message = failure("1 2 3 0\n4 5 6 0\n7 8 inf 0\n");
  CHECK_MESSAGE(contains(message, "bad.ply:11:"), message);

  message = failure("1 2 3 0\n4 5 6\n7 8 9 0\n");
  CHECK_MESSAGE(contains(message, "bad.ply:10:"), message);

  message = failure("1 2 3 0\n4 5 1e39 0\n7 8 9 0\n");  // beyond float range
  CHECK_MESSAGE(contains(message, "bad.ply:10:"), message);

  message = failure("1 2 3 0\n4 5 6 0 0\n7 8 9 0\n");
  CHECK_MESSAGE(contains(message, "bad.ply:10:"), message);

  message = failure("1 2 3 0\n4 5 6 1.5\n7 8 9 0\n");
  CHECK_MESSAGE(contains(message, "bad.ply:10:"), message);

  message = failure("1 2 3 0\n4 5 6 4294967296\n7 8 9 0\n");
  CHECK_MESSAGE(contains(message, "bad.ply:10:"), message);

  message = failure("1 2 3 0\n4 5 6 0\n");
  CHECK_MESSAGE(contains(message, "bad.ply:10:"), message);
  CHECK_MESSAGE(contains(message, "2 of 3"), message);

  // A face list longer than its line.
  writeText(path,
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
            "property float z\nproperty list uchar int idx\nend_header\n1 2 3 4 0 1\n");
  message = errorOf([&] { readPly(path); });
  CHECK_MESSAGE(contains(message, "bad.ply:9:"), message);
}

TEST_CASE("ply: bad binary bodies fail naming file and byte") {
  TempDir dir;
  const auto path = dir / "bad.ply";
  const auto headerFor = [](const std::string& count) {
    return "ply\nformat binary_little_endian 1.0\nelement vertex " + count +
           "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  };

  // Truncated: 3 vertices claimed, 2.5 present.
  std::string bytes = headerFor("3");
  const std::size_t body_start = bytes.size();
  for (int i = 0; i < 7; ++i) put<float>(bytes, 1.0F);
  put<std::uint16_t>(bytes, 0);
  writeText(path, bytes);
  std::string message = errorOf([&] { readPly(path); });
  CHECK_MESSAGE(contains(message, "bad.ply: byte " + std::to_string(body_start + 30)), message);
  CHECK_MESSAGE(contains(message, "3 vertex expected"), message);

  // 10^12 vertices claimed: rejected before anything is allocated for them.
  bytes = headerFor("1000000000000");
  for (int i = 0; i < 30; ++i) put<float>(bytes, 1.0F);
  writeText(path, bytes);
  const auto start = std::chrono::steady_clock::now();
  message = errorOf([&] { readPly(path); });
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(1));
  CHECK_MESSAGE(contains(message, "bad.ply: byte "), message);
  CHECK_MESSAGE(contains(message, "1000000000000"), message);

  // Also for ascii.
  writeText(path, "ply\nformat ascii 1.0\nelement vertex 1000000000000\nproperty float x\n"
                  "property float y\nproperty float z\nend_header\n1 2 3\n");
  message = errorOf([&] { readPly(path); });
  CHECK_MESSAGE(contains(message, "bad.ply:8:"), message);

  // The header is the whole file, without a final newline.
  bytes = headerFor("1");
  bytes.pop_back();
  writeText(path, bytes);
  message = errorOf([&] { readPly(path); });
  CHECK_MESSAGE(contains(message, "bad.ply: byte " + std::to_string(bytes.size())), message);
  bytes = headerFor("0");
  bytes.pop_back();
  writeText(path, bytes);
  CHECK(readPly(path).size() == 0);

  // NaN coordinate in binary.
  bytes = headerFor("2");
  const std::size_t second_row = bytes.size() + 12;
  for (float value : {1.0F, 2.0F, 3.0F, 4.0F, std::nanf(""), 6.0F}) put<float>(bytes, value);
  writeText(path, bytes);
  message = errorOf([&] { readPly(path); });
  CHECK_MESSAGE(contains(message, "bad.ply: byte " + std::to_string(second_row)), message);

  // A list before the vertices whose length runs past the end of the file.
  bytes = "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list int int idx\n"
          "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  const std::size_t list_start = bytes.size();
  put<std::int32_t>(bytes, 2000000000);
  for (int i = 0; i < 3; ++i) put<float>(bytes, 1.0F);
  writeText(path, bytes);
  message = errorOf([&] { readPly(path); });
  CHECK_MESSAGE(contains(message, "bad.ply: byte " + std::to_string(list_start + 16)), message);

  // A negative list length.
  bytes = "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list int int idx\n"
          "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  put<std::int32_t>(bytes, -1);
  for (int i = 0; i < 3; ++i) put<float>(bytes, 1.0F);
  writeText(path, bytes);
  message = errorOf([&] { readPly(path); });
  CHECK_MESSAGE(contains(message, "bad.ply: byte " + std::to_string(list_start)), message);
}

TEST_CASE("ply: random corruption of a binary file never crashes") {
  TempDir dir;
  Scan scan = randomScan(50, true, 3);
  writePly(dir / "good.ply", scan);
  const std::string good = mlmap::test::readText(dir / "good.ply");
  const int failures = mlmap::test::readCorruptedCopies(
      good, dir / "bad.ply", 11, [](const auto& path) { return readPly(path); });
  CHECK(failures > 0);
}
