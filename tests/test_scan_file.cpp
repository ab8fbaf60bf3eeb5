#include <doctest/doctest.h>

#include <string>

#include "helpers.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/scan_file.hpp"

using mlmap::Error;
using mlmap::Point;
using mlmap::Scan;
using mlmap::io::readScans;
using mlmap::io::writeScan;
using mlmap::test::checkSamePoints;
using mlmap::test::readText;
using mlmap::test::TempDir;
using mlmap::test::writeText;

namespace {

Scan smallScan() {
  Scan scan;
  scan.points = {{1.25, -2.5, 0.5}, {3.0, 4.0, -1.0}, {-0.125, 0.0, 2.75}};
  scan.pose.translation() = Eigen::Vector3d(1.0, 2.0, 0.0);
  scan.pose.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return scan;
}

}  // namespace

TEST_CASE("scan_file: every extension reaches its format, case-insensitively") {
  TempDir dir;
  const Scan scan = smallScan();

  SUBCASE("xyz family") {
    for (const char* name : {"a.xyz", "b.TXT", "c.Pts", "d.dat", "e.XYZ"}) {
      CAPTURE(name);
      writeScan(dir / name, scan);
      CHECK(readText(dir / name).substr(0, 12) == "1.25 -2.5 0.");
      const auto back = readScans(dir / name);
      REQUIRE(back.size() == 1);
      checkSamePoints(back[0], scan, 1e-9);
    }
  }
  SUBCASE("ply") {
    writeScan(dir / "a.PLY", scan);
    CHECK(readText(dir / "a.PLY").substr(0, 4) == "ply\n");
    const auto back = readScans(dir / "a.PLY");
    REQUIRE(back.size() == 1);
    checkSamePoints(back[0], scan, 1e-5);
  }
  SUBCASE("pcd") {
    writeScan(dir / "a.Pcd", scan);
    CHECK(readText(dir / "a.Pcd").find("FIELDS") != std::string::npos);
    const auto back = readScans(dir / "a.Pcd");
    REQUIRE(back.size() == 1);
    checkSamePoints(back[0], scan, 1e-5);
  }
  SUBCASE("3dtk keeps the pose") {
    writeScan(dir / "scan000.3D", scan);
    CHECK(std::filesystem::exists(dir / "scan000.pose"));
    const auto back = readScans(dir / "scan000.3D");
    REQUIRE(back.size() == 1);
    checkSamePoints(back[0], scan, 1e-9);
    CHECK(back[0].pose.isApprox(scan.pose, 1e-9));
  }
  SUBCASE("graph keeps the pose") {
    writeScan(dir / "one.GRAPH", scan);
    const auto back = readScans(dir / "one.GRAPH");
    REQUIRE(back.size() == 1);
    checkSamePoints(back[0], scan, 1e-5);
    CHECK(back[0].pose.isApprox(scan.pose, 1e-6));
  }
}

TEST_CASE("scan_file: unknown extension names the file and the supported list") {
  TempDir dir;
  writeText(dir / "cloud.las", "whatever");
  CHECK_THROWS_WITH_AS(readScans(dir / "cloud.las"),
                       doctest::Contains("cloud.las: unknown scan format '.las' (supported: .xyz"),
                       Error);
  CHECK_THROWS_WITH_AS(writeScan(dir / "noextension", smallScan()),
                       doctest::Contains("noextension"), Error);
  CHECK_FALSE(std::filesystem::exists(dir / "noextension"));
}

TEST_CASE("scan_file: missing file") {
  TempDir dir;
  for (const char* name : {"gone.xyz", "gone.ply", "gone.pcd", "gone.3d", "gone.graph"}) {
    CAPTURE(name);
    CHECK_THROWS_WITH_AS(readScans(dir / name),
                         doctest::Contains((std::string(name) + ": no such file").c_str()), Error);
  }
}

TEST_CASE("scan_file: reader errors pass through with file and line") {
  TempDir dir;
  writeText(dir / "bad.txt", "1 2 3\n4 5 six\n");
  CHECK_THROWS_WITH_AS(readScans(dir / "bad.txt"), doctest::Contains("bad.txt:2"), Error);
}
