// PCD reader and writer: round trips of all three encodings, hand-made files with
// padding and multi-value fields, PCL's own test clouds, and hostile input that
// must fail with file and line/byte.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <optional>
#include <set>
#include <string>

#include "helpers.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/pcd.hpp"

using mlmap::Point;
using mlmap::Pose;
using mlmap::Scan;
using mlmap::io::PcdEncoding;
using mlmap::io::readPcd;
using mlmap::io::writePcd;
using mlmap::test::contains;
using mlmap::test::errorOf;
using mlmap::test::LabelRange;
using mlmap::test::put;
using mlmap::test::TempDir;
using mlmap::test::writeText;

namespace {

Scan randomScan(std::size_t count, bool with_labels, bool negative_labels, unsigned seed) {
  Scan scan = mlmap::test::randomScan(
      count, seed, 50.0,
      with_labels ? std::optional(LabelRange{negative_labels ? -1000 : 0, 2000000}) : std::nullopt);
  scan.pose = Pose::Identity();
  scan.pose.translate(Eigen::Vector3d(1.5, -2.25, 0.75));
  scan.pose.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  return scan;
}

// A valid LZF stream made of literal runs only (control byte = run length - 1),
// so hand-made compressed files do not depend on our writer.
std::string lzfLiterals(const std::string& data) {
  std::string out;
  for (std::size_t start = 0; start < data.size(); start += 32) {
    const std::size_t length = std::min<std::size_t>(32, data.size() - start);
    out += static_cast<char>(length - 1);
    out.append(data, start, length);
  }
  return out;
}

}  // namespace

TEST_CASE("pcd: round trip of every encoding, with and without labels") {
  TempDir dir;
  for (const PcdEncoding encoding :
       {PcdEncoding::Ascii, PcdEncoding::Binary, PcdEncoding::BinaryCompressed}) {
    for (const int labels : {0, 1, 2}) {  // none, unsigned, with negatives
      CAPTURE(static_cast<int>(encoding));
      CAPTURE(labels);
      const Scan written = randomScan(2000, labels > 0, labels == 2, 5);
      const auto path = dir / "cloud.pcd";
      writePcd(path, written, encoding);
      const Scan read = readPcd(path);
      // Written as float: each coordinate rounded to 24 bits (relative error 2^-24).
      CHECK(mlmap::test::maxRelativeError(read, written) < 1e-7);
      CHECK(read.labels == written.labels);
      CHECK(read.pose.isApprox(written.pose, 1e-12));
    }
  }
}

TEST_CASE("pcd: writer marks labels unsigned unless one is negative") {
  TempDir dir;
  Scan scan = randomScan(3, true, false, 1);
  writePcd(dir / "u.pcd", scan, PcdEncoding::Ascii);
  CHECK(contains(mlmap::test::readText(dir / "u.pcd"), "TYPE F F F U\n"));
  scan.labels[1] = -1;
  writePcd(dir / "i.pcd", scan, PcdEncoding::Ascii);
  CHECK(contains(mlmap::test::readText(dir / "i.pcd"), "TYPE F F F I\n"));
  CHECK(contains(mlmap::test::readText(dir / "i.pcd"), " -1\n"));
}

TEST_CASE("pcd: an empty scan round-trips in every encoding") {
  TempDir dir;
  for (const PcdEncoding encoding :
       {PcdEncoding::Ascii, PcdEncoding::Binary, PcdEncoding::BinaryCompressed}) {
    writePcd(dir / "empty.pcd", Scan{}, encoding);
    const Scan read = readPcd(dir / "empty.pcd");
    CHECK(read.size() == 0);
    CHECK(read.pose.isApprox(Pose::Identity()));
  }
}

TEST_CASE("pcd: writer rejects labels that do not match the points") {
  TempDir dir;
  Scan scan = randomScan(3, true, false, 1);
  scan.labels.push_back(1);
  CHECK_THROWS_AS(writePcd(dir / "x.pcd", scan), mlmap::Error);
  CHECK_FALSE(std::filesystem::exists(dir / "x.pcd"));
}

TEST_CASE("pcd: ascii without VERSION, with padding, COUNT>1 fields and NaN points") {
  TempDir dir;
  writeText(dir / "a.pcd",
            "# hand-made\n"
            "FIELDS x y z intensity normal _ label\n"
            "SIZE 4 4 4 4 4 1 4\n"
            "TYPE F F F F F U U\n"
            "COUNT 1 1 1 1 3 2 1\n"
            "WIDTH 2\n"
            "HEIGHT 2\n"
            "VIEWPOINT 1 2 3 0 1 0 0\n"
            "POINTS 4\n"
            "DATA ascii\n"
            "1 2 3 0.5 0 0 1 0 0 7\n"
            "nan nan nan 0 0 0 0 0 0 8\n"
            "-4.5 5e-3 6 9 0 1 0 0 0 4294967\n"
            "7 NaN 9 9 0 1 0 0 0 10\n");
  const Scan scan = readPcd(dir / "a.pcd");
  REQUIRE(scan.size() == 2);
  CHECK(scan.points[0] == Point(1, 2, 3));
  CHECK(scan.points[1] == Point(-4.5, 0.005F, 6));  // F 4: rounded to float as in a binary file
  CHECK(scan.labels == std::vector<std::int32_t>{7, 4294967});
  // qw=0, qx=1: half a turn about x.
  CHECK(scan.pose.translation() == Eigen::Vector3d(1, 2, 3));
  CHECK(scan.pose.linear().isApprox(Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix()));
  CHECK(scan.from_image);  // HEIGHT 2: organized, a depth image's rows (the up axis's cue)
}

TEST_CASE("pcd: other spellings of VERSION are accepted") {
  TempDir dir;
  for (const std::string version : {"0.7", ".7", "v.7", "v0.7", "0.6"}) {
    writeText(dir / "v.pcd", "VERSION " + version +
                                 "\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n");
    const Scan scan = readPcd(dir / "v.pcd");
    REQUIRE(scan.size() == 1);
    CHECK(scan.points[0] == Point(1, 2, 3));
  }
}

TEST_CASE("pcd: binary with double coordinates, x not first, padding and a NaN point") {
  TempDir dir;
  std::string bytes =
      "VERSION 0.7\nFIELDS rgb x y z _ label\nSIZE 4 8 8 8 1 2\nTYPE U F F F I U\n"
      "COUNT 1 1 1 1 3 1\nWIDTH 2\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA binary\n";
  const double nan = std::nan("");
  const double coordinates[4][3] = {{0.1, 0.2, 0.3}, {nan, nan, nan}, {-1e5, 1e-7, 2}, {4, 5, nan}};
  for (int i = 0; i < 4; ++i) {
    put<std::uint32_t>(bytes, 0xffffffffU);
    for (int k = 0; k < 3; ++k) put<double>(bytes, coordinates[i][k]);
    bytes.append(3, '\x55');
    put<std::uint16_t>(bytes, static_cast<std::uint16_t>(60000 + i));
  }
  writeText(dir / "b.pcd", bytes);
  const Scan scan = readPcd(dir / "b.pcd");
  REQUIRE(scan.size() == 2);
  CHECK(scan.points[0] == Point(0.1, 0.2, 0.3));  // doubles kept exactly
  CHECK(scan.points[1] == Point(-1e5, 1e-7, 2));
  CHECK(scan.labels == std::vector<std::int32_t>{60000, 60002});
}

TEST_CASE("pcd: hand-made binary_compressed is decoded field by field") {
  TempDir dir;
  // Fields x y z _(U1 x3) normal(F4 x2) label(I4); three points, the middle one NaN.
  const float x[3] = {1, std::nanf(""), 3}, y[3] = {-1, std::nanf(""), -3}, z[3] = {0.5F, 0, 2.5F};
  const std::int32_t labels[3] = {-7, 99, 123456};
  std::string unpacked;
  for (float v : x) put<float>(unpacked, v);
  for (float v : y) put<float>(unpacked, v);
  for (float v : z) put<float>(unpacked, v);
  unpacked.append(9, '\x7f');
  for (int i = 0; i < 6; ++i) put<float>(unpacked, 42.0F);
  for (std::int32_t v : labels) put<std::int32_t>(unpacked, v);
  REQUIRE(unpacked.size() == 3 * (12 + 3 + 8 + 4));
  const std::string packed = lzfLiterals(unpacked);
  std::string bytes =
      "VERSION 0.7\nFIELDS x y z _ normal label\nSIZE 4 4 4 1 4 4\nTYPE F F F U F I\n"
      "COUNT 1 1 1 3 2 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\n"
      "DATA binary_compressed\n";
  put<std::uint32_t>(bytes, static_cast<std::uint32_t>(packed.size()));
  put<std::uint32_t>(bytes, static_cast<std::uint32_t>(unpacked.size()));
  bytes += packed;
  writeText(dir / "c.pcd", bytes);
  const Scan scan = readPcd(dir / "c.pcd");
  REQUIRE(scan.size() == 2);
  CHECK(scan.points[0] == Point(1, -1, 0.5));
  CHECK(scan.points[1] == Point(3, -3, 2.5));
  CHECK(scan.labels == std::vector<std::int32_t>{-7, 123456});
}

TEST_CASE("pcd: PCL's test clouds") {
  const auto data = mlmap::test::sharedDataDir();
  if (!data) {
    MESSAGE("skipped: no shared data directory");
    return;
  }
  SUBCASE("office1.pcd: organized 640x480 binary_compressed with rgb") {
    const Scan scan = readPcd(*data / "pcl_test_indoor" / "office1.pcd");
    CHECK(scan.size() > 0);
    CHECK(scan.size() < 307200);
    CHECK(scan.labels.empty());
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double farthest = 0.0;
    for (const Point& point : scan.points) {
      farthest = std::max(farthest, point.norm());
      sum += point;
    }
    CHECK(std::isfinite(farthest));
    CHECK(farthest < 20.0);  // m: an office seen by a Kinect
    const Eigen::Vector3d mean = sum / static_cast<double>(scan.size());
    CHECK(mean.z() > 0.5);  // camera frame: z forward
    CHECK(mean.z() < 10.0);
    // VIEWPOINT 0 0 0 0 1 0 0: half a turn about x.
    CHECK(scan.pose.linear().isApprox(Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix()));
    CHECK(scan.from_image);
    MESSAGE("office1.pcd: " << scan.size() << " finite points");
  }
  SUBCASE("table_scene_mug_stereo_textured.pcd: binary_compressed with rgba") {
    const Scan scan = readPcd(*data / "pcl_test_indoor" / "table_scene_mug_stereo_textured.pcd");
    CHECK(scan.size() > 0);
    CHECK(scan.size() < 307200);
    double farthest = 0.0;
    for (const Point& point : scan.points) farthest = std::max(farthest, point.norm());
    CHECK(std::isfinite(farthest));
    CHECK(farthest < 20.0);
  }
  SUBCASE("sac_plane_test.pcd: ascii with normals and curvature") {
    const Scan scan = readPcd(*data / "pcl_test_indoor" / "sac_plane_test.pcd");
    CHECK(scan.size() == 3283);
    CHECK(scan.points[0] == Point(1.068F, 0.094720997F, -0.016231F));
    CHECK(scan.labels.empty());
    CHECK_FALSE(scan.from_image);  // HEIGHT 1: unorganized
  }
}

TEST_CASE("pcd: Bobkov et al. labelled office room") {
  const auto data = mlmap::test::sharedDataDir();
  if (!data) {
    MESSAGE("skipped: no shared data directory");
    return;
  }
  const Scan scan = readPcd(*data / "bobkov_office_labels" / "room2_gt_coarse.pcd");
  CHECK(scan.size() == 123692);
  REQUIRE(scan.labels.size() == scan.size());
  // The first data line is "0 0 1.5 4".
  CHECK(scan.points[0] == Point(0, 0, 1.5));
  CHECK(scan.labels[0] == 4);
  const std::set<std::int32_t> distinct(scan.labels.begin(), scan.labels.end());
  CHECK(distinct.size() == 14);
  CHECK(distinct.count(0) == 1);
}

TEST_CASE("pcd: bad headers fail naming file and line") {
  TempDir dir;
  const auto path = dir / "bad.pcd";
  const auto failure = [&](const std::string& text) {
    return mlmap::test::errorReading(path, text, readPcd);
  };
  std::string message = failure("ply\nformat ascii 1.0\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:1:"), message);

  message = failure("");
  CHECK_MESSAGE(contains(message, "DATA"), message);

  message = failure("VERSION 0.9\nFIELDS x y z\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:1:"), message);

  message = failure("# c\nFIELDS a y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:2:"), message);

  message = failure("FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:2:"), message);

  message = failure("FIELDS x y z\nSIZE 4 4 3\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:2:"), message);

  message = failure("FIELDS x y z\nSIZE 4 4 4\nTYPE F F U\nWIDTH 1\nDATA ascii\n1 2 3\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:3:"), message);

  message = failure("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 2 1\nWIDTH 1\nDATA ascii\n1 2 3\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:3:"), message);

  message = failure("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 2\nPOINTS 5\n"
                    "DATA ascii\n1 2 3\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:6:"), message);
  CHECK_MESSAGE(contains(message, "POINTS"), message);

  message = failure("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nDATA zip\n1 2 3\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:5:"), message);

  message = failure("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nVIEWPOINT 0 0 0 0 0 0 0\n"
                    "DATA ascii\n1 2 3\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:5:"), message);

  message = failure("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nWIDTH 1\nDATA ascii\n1 2 3\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:5:"), message);

  message = failure("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nDATA ascii\n1 2 3\n");
  CHECK_MESSAGE(contains(message, "WIDTH"), message);

  CHECK_THROWS_AS(readPcd(dir / "missing.pcd"), mlmap::Error);
}

TEST_CASE("pcd: bad ascii bodies fail naming file and line") {
  TempDir dir;
  const auto path = dir / "bad.pcd";
  const std::string header =
      "FIELDS x y z label\nSIZE 4 4 4 4\nTYPE F F F U\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n";
  const auto failure = [&](const std::string& body) {
    return mlmap::test::errorReading(path, header + body, readPcd);
  };
  std::string message = failure("1 2 3 0\n4 inf 6 0\n7 8 9 0\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:9:"), message);

  message = failure("1 2 3 0\n4 5 6 0\n7 8 x 0\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:10:"), message);

  message = failure("1 2 3 0\n4 5 6\n7 8 9 0\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:9:"), message);

  message = failure("1 2 3 0\n4 5 -1e39 0\n7 8 9 0\n");  // beyond float range
  CHECK_MESSAGE(contains(message, "bad.pcd:9:"), message);

  message = failure("1 2 3 0\n4 5 6 4294967295\n7 8 9 0\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:9:"), message);

  message = failure("1 2 3 0\n4 5 6 -1\n7 8 9 0\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:9:"), message);

  message = failure("1 2 3 0\n4 5 6 0\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:9:"), message);
  CHECK_MESSAGE(contains(message, "2 of 3"), message);

  message = failure("1 2 3 0\n4 5 6 0\n7 8 9 0\n1 1 1 1\n");
  CHECK_MESSAGE(contains(message, "bad.pcd:11:"), message);

  // A WIDTH the file cannot hold is not allocated for.
  writeText(path, "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1000000000000\nDATA ascii\n1 2 3\n");
  message = errorOf([&] { readPcd(path); });
  CHECK_MESSAGE(contains(message, "bad.pcd:6:"), message);
}

TEST_CASE("pcd: bad binary bodies fail naming file and byte") {
  TempDir dir;
  const auto path = dir / "bad.pcd";
  const auto headerFor = [](const std::string& width, const std::string& data) {
    return "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH " + width + "\nHEIGHT 1\nDATA " + data + "\n";
  };

  // Truncated: 4 points claimed, 3.5 present.
  std::string bytes = headerFor("4", "binary");
  std::size_t body_start = bytes.size();
  for (int i = 0; i < 10; ++i) put<float>(bytes, 1.0F);
  put<std::uint16_t>(bytes, 0);
  writeText(path, bytes);
  std::string message = errorOf([&] { readPcd(path); });
  CHECK_MESSAGE(contains(message, "bad.pcd: byte " + std::to_string(body_start + 42)), message);
  CHECK_MESSAGE(contains(message, "4 points"), message);

  // The header is the whole file, without a final newline.
  for (const std::string data : {"binary", "binary_compressed"}) {
    bytes = headerFor("1", data);
    bytes.pop_back();
    writeText(path, bytes);
    message = errorOf([&] { readPcd(path); });
    CHECK_MESSAGE(contains(message, "bad.pcd: byte " + std::to_string(bytes.size())), message);
    bytes = headerFor("0", data);
    bytes.pop_back();
    writeText(path, bytes);
    CHECK(readPcd(path).size() == 0);
  }

  // A huge organized cloud claimed: rejected before allocating.
  bytes = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4000000000\nHEIGHT 100000\nDATA binary\n";
  for (int i = 0; i < 30; ++i) put<float>(bytes, 1.0F);
  writeText(path, bytes);
  const auto start = std::chrono::steady_clock::now();
  message = errorOf([&] { readPcd(path); });
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(1));
  CHECK_MESSAGE(contains(message, "bad.pcd: byte "), message);
  CHECK_MESSAGE(contains(message, "400000000000000 points"), message);

  // A binary label that does not fit int32.
  bytes = "FIELDS x y z label\nSIZE 4 4 4 8\nTYPE F F F I\nWIDTH 1\nDATA binary\n";
  body_start = bytes.size();
  for (int i = 0; i < 3; ++i) put<float>(bytes, 1.0F);
  put<std::int64_t>(bytes, std::int64_t{1} << 40);
  writeText(path, bytes);
  message = errorOf([&] { readPcd(path); });
  CHECK_MESSAGE(contains(message, "bad.pcd: byte " + std::to_string(body_start + 12)), message);

  // binary_compressed cases, 2 points of 12 bytes.
  std::string unpacked;
  for (int i = 0; i < 6; ++i) put<float>(unpacked, static_cast<float>(i));
  const std::string packed = lzfLiterals(unpacked);
  const auto compressed = [&](std::uint32_t compressed_size, std::uint32_t uncompressed_size,
                              const std::string& payload) {
    std::string file = headerFor("2", "binary_compressed");
    put<std::uint32_t>(file, compressed_size);
    put<std::uint32_t>(file, uncompressed_size);
    return file + payload;
  };
  body_start = headerFor("2", "binary_compressed").size();

  writeText(path, compressed(static_cast<std::uint32_t>(packed.size()), 24, packed));
  REQUIRE(readPcd(path).size() == 2);  // the well-formed file the cases below break

  writeText(path, compressed(static_cast<std::uint32_t>(packed.size()), 25, packed));
  message = errorOf([&] { readPcd(path); });
  CHECK_MESSAGE(contains(message, "bad.pcd: byte " + std::to_string(body_start + 4)), message);

  writeText(path, compressed(static_cast<std::uint32_t>(packed.size()) + 1, 24, packed));
  message = errorOf([&] { readPcd(path); });
  CHECK_MESSAGE(contains(message, "bad.pcd: byte " + std::to_string(body_start + 8 + packed.size())),
                message);

  // A back reference before the start of the output.
  writeText(path, compressed(3, 24, std::string("\xe0\x05\x40", 3)));
  message = errorOf([&] { readPcd(path); });
  CHECK_MESSAGE(contains(message, "bad.pcd: byte " + std::to_string(body_start + 8)), message);

  // Decompresses to fewer bytes than declared.
  const std::string short_packed = lzfLiterals(unpacked.substr(0, 20));
  writeText(path, compressed(static_cast<std::uint32_t>(short_packed.size()), 24, short_packed));
  message = errorOf([&] { readPcd(path); });
  CHECK_MESSAGE(contains(message, "bad.pcd: byte " + std::to_string(body_start + 8)), message);

  // 4 GB declared from 10 bytes: no LZF stream expands that much, nothing is allocated.
  bytes = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 100000000\nHEIGHT 3\n"
          "DATA binary_compressed\n";
  body_start = bytes.size();
  put<std::uint32_t>(bytes, 10);
  put<std::uint32_t>(bytes, 3600000000U);
  bytes.append(10, '\0');
  writeText(path, bytes);
  message = errorOf([&] { readPcd(path); });
  CHECK_MESSAGE(contains(message, "bad.pcd: byte " + std::to_string(body_start)), message);

  // No room even for the two sizes.
  const std::string too_short = headerFor("2", "binary_compressed") + "abc";
  writeText(path, too_short);
  message = errorOf([&] { readPcd(path); });
  CHECK_MESSAGE(contains(message, "bad.pcd: byte " + std::to_string(too_short.size())), message);
}

TEST_CASE("pcd: an LZF block that expands past its declared size is refused") {
  TempDir dir;
  const auto path = dir / "long.pcd";
  // One point (12 bytes) declared, sizes consistent, but the block expands to 24 bytes:
  // the decompressor stops at the declared size instead of writing past it.
  std::string unpacked;
  for (int i = 0; i < 6; ++i) put<float>(unpacked, static_cast<float>(i));
  const std::string packed = lzfLiterals(unpacked);
  std::string bytes = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nDATA binary_compressed\n";
  const std::size_t body_start = bytes.size();
  put<std::uint32_t>(bytes, static_cast<std::uint32_t>(packed.size()));
  put<std::uint32_t>(bytes, 12);
  writeText(path, bytes + packed);
  const std::string message = errorOf([&] { readPcd(path); });
  CHECK_MESSAGE(contains(message, "long.pcd: byte " + std::to_string(body_start + 8)), message);
  CHECK_MESSAGE(contains(message, "declared 12 bytes"), message);
}

TEST_CASE("pcd: random corruption of binary and compressed files never crashes") {
  TempDir dir;
  const Scan scan = randomScan(200, true, false, 3);
  for (const PcdEncoding encoding : {PcdEncoding::Binary, PcdEncoding::BinaryCompressed}) {
    writePcd(dir / "good.pcd", scan, encoding);
    const std::string good = mlmap::test::readText(dir / "good.pcd");
    const int failures = mlmap::test::readCorruptedCopies(
        good, dir / "bad.pcd", 17, [](const auto& path) { return readPcd(path); });
    CHECK(failures > 0);
  }
}
