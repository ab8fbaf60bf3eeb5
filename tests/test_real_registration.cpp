// Registration on real scans nobody here made (issue 20): PCL's two scans of one room, from
// the odometry start PCL's NDT tutorial gives. Skipped where ../shared/data is absent.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "helpers.hpp"
#include "mlmap/io/pcd.hpp"
#include "mlmap/registration/sequence_registration.hpp"

using namespace mlmap::registration;

namespace {

// room_scan2 -> room_scan1: PCL's NDT tutorial's odometry guess, and the transform the data's
// README found by point-to-plane ICP from it (Open3D and PCL land within 0.2 cm / 0.08° of it).
mlmap::Pose ndtStart() {
  mlmap::Pose pose = mlmap::Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(0.6931, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(1.79387, 0.720047, 0.0);
  return pose;
}

mlmap::Pose readmeTransform() {
  Eigen::Matrix4d m;
  m << 0.75637, -0.65378, 0.02168, 1.97081, 0.65362, 0.75668, 0.01467, 0.05699, -0.02599, 0.00308, 0.99966, 0.02532,
      0, 0, 0, 1;
  mlmap::Pose pose = mlmap::Pose::Identity();
  pose.linear() = Eigen::Quaterniond(m.topLeftCorner<3, 3>()).normalized().toRotationMatrix();
  pose.translation() = m.topRightCorner<3, 1>();
  return pose;
}

// `mlmap register`'s range limits.
SequenceConfig registerConfig() {
  SequenceConfig config;
  config.min_range = 0.4;
  config.max_range = 30.0;
  return config;
}

}  // namespace

TEST_CASE("Real scans: PCL's room_scan2 registers onto room_scan1 from PCL's odometry start") {
  const auto data = mlmap::test::sharedDataDir();
  if (!data) {
    MESSAGE("skipped: no shared data directory");
    return;
  }
  const mlmap::Scan first = mlmap::io::readPcd(*data / "pcl_room_scans" / "room_scan1.pcd");
  const mlmap::Scan second = mlmap::io::readPcd(*data / "pcl_room_scans" / "room_scan2.pcd");
  const mlmap::Pose reference = readmeTransform();
  const auto offBy = [&](const mlmap::Pose& pose) {
    const mlmap::Pose error = reference.inverse() * pose;
    return std::pair{error.translation().norm(), Eigen::AngleAxisd(error.linear()).angle() * 180.0 / std::numbers::pi};
  };

  SUBCASE("measured noise: the right transform, kept though nothing verifies") {
    // Two real scans disagree by more than each one's own noise (1.75 cm residual spread at
    // the transform against 0.69 cm expected): no run is "good". The first run stopped 0.66 m
    // off, unconstrained, and was kept over the wide retry's right answer.
    SequenceRegistration sequence(registerConfig());
    sequence.addScan(first.points, mlmap::Pose::Identity());
    const VerifiedIcp result = sequence.addScan(second.points, ndtStart());
    const auto [metres, degrees] = offBy(result.icp.pose);
    CAPTURE(result.reason);
    CHECK(metres < 0.02);
    CHECK(degrees < 0.3);
    CHECK_FALSE(result.verified);
    CHECK(result.attempts <= 6);  // two starts agreeing end the retries (12 before)
  }
  SUBCASE("the scans' disagreement given: verified") {
    SequenceConfig config = registerConfig();
    config.basin.noise = config.basin.source_noise = 0.012;
    SequenceRegistration sequence(config);
    sequence.addScan(first.points, mlmap::Pose::Identity());
    const VerifiedIcp result = sequence.addScan(second.points, ndtStart());
    const auto [metres, degrees] = offBy(result.icp.pose);
    CAPTURE(result.reason);
    CHECK(result.verified);
    CHECK(metres < 0.02);
    CHECK(degrees < 0.3);
  }
}
