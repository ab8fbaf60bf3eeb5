// Eq. 4: the DH chain against hand-computed points; the mount config file.
#include <doctest/doctest.h>

#include <numbers>

#include "helpers.hpp"
#include "mlmap/driver/kinematics.hpp"

using namespace mlmap::driver;

namespace {
constexpr double kPi = std::numbers::pi;

void checkPoint(const mlmap::Point& got, const Eigen::Vector3d& expected) {
  CAPTURE(got.transpose());
  CAPTURE(expected.transpose());
  CHECK((got - expected).norm() < 1e-12);
}
}  // namespace

TEST_CASE("Kinematics: hand-computed points without offsets") {
  const MountConfig mount;
  checkPoint(beamPoint(mount, 0.0, 0.0, 0.0, 2.0), {2.0, 0.0, 0.0});
  checkPoint(beamPoint(mount, 0.0, 0.0, kPi / 2, 2.0), {0.0, 2.0, 0.0});   // λ: left
  checkPoint(beamPoint(mount, kPi / 2, 0.0, 0.0, 2.0), {0.0, 2.0, 0.0});   // α: pan left
  checkPoint(beamPoint(mount, 0.0, kPi / 2, 0.0, 2.0), {0.0, 0.0, -2.0});  // γ: nose down
  // γ = 30° nose-down, λ = 90°: the beam sweeps sideways, unaffected by the tilt.
  checkPoint(beamPoint(mount, 0.0, kPi / 6, kPi / 2, 1.0), {0.0, 1.0, 0.0});
  // The simulator's beam: R_y(γ)·(cos λ, sin λ, 0).
  const double gamma = 0.3, lambda = -0.7;
  checkPoint(beamPoint(mount, 0.0, gamma, lambda, 3.0),
             3.0 * Eigen::Vector3d(std::cos(gamma) * std::cos(lambda), std::sin(lambda),
                                   -std::sin(gamma) * std::cos(lambda)));
}

TEST_CASE("Kinematics: mounting offsets u and the tilt axis height") {
  MountConfig mount;
  mount.tilt_axis_height = 0.2;
  mount.laser_offset = Eigen::Vector3d(0.1, 0.0, 0.05);
  // γ = 90°: forward offset and range point down, the 5 cm lift points forward.
  checkPoint(beamPoint(mount, 0.0, kPi / 2, 0.0, 1.0), {0.05, 0.0, 0.2 - 1.1});
  // Lateral offset u_y lies on the tilt axis: the tilt does not move it.
  mount.laser_offset = Eigen::Vector3d(0.0, 0.03, 0.0);
  checkPoint(beamPoint(mount, 0.0, 0.4, 0.0, 0.0), {0.0, 0.03, 0.2});
  // Pan 90° turns it all about z.
  checkPoint(beamPoint(mount, kPi / 2, 0.0, 0.0, 1.0), {-0.03, 1.0, 0.2});
  const Beam beam = beamAt(mount, kPi / 2, 0.0, 0.0);
  checkPoint(beam.origin, {-0.03, 0.0, 0.2});
  checkPoint(beam.direction, {0.0, 1.0, 0.0});
  // A single DH link: Rot_z(90°) then a = 1 along the new x.
  const Eigen::Matrix4d link = dhLink(kPi / 2, 0.5, 1.0, 0.0);
  CHECK((link.block<3, 1>(0, 3) - Eigen::Vector3d(0.0, 1.0, 0.5)).norm() < 1e-12);
}

TEST_CASE("Kinematics: mount config JSON") {
  const MountConfig mount =
      parseMountConfig(R"({"tilt_axis_height": 0.07, "laser_offset": [0.01, -0.02, 0.04]})", "mount.json");
  CHECK(mount.tilt_axis_height == 0.07);
  CHECK(mount.laser_offset.y() == -0.02);
  CHECK(parseMountConfig("{}", "empty.json").laser_offset.isZero());
  auto error = [](const std::string& text) {
    return mlmap::test::errorOf([&] { parseMountConfig(text, "mount.json"); });
  };
  CHECK(mlmap::test::contains(error("{"), "mount.json: bad JSON"));
  CHECK(mlmap::test::contains(error(R"({"laser_offset": [1, 2]})"), "laser_offset: expected 3 numbers"));
  CHECK(mlmap::test::contains(error(R"({"laser_offset": [1, "a", 2]})"), "laser_offset[1]"));
  CHECK(mlmap::test::contains(error(R"({"tilt_axis_hieght": 1})"), "unknown field 'tilt_axis_hieght'"));
  CHECK(mlmap::test::contains(error("[1]"), "expected a JSON object"));
  mlmap::test::TempDir dir;
  mlmap::test::writeText(dir / "mount.json", R"({"tilt_axis_height": 0.5})");
  CHECK(loadMountConfig(dir / "mount.json").tilt_axis_height == 0.5);
  CHECK(mlmap::test::contains(mlmap::test::errorOf([&] { loadMountConfig(dir / "missing.json"); }),
                              "missing.json: cannot open"));
}
