// Absolute trajectory error on hand-made pose lists.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

#include "mlmap/error.hpp"
#include "mlmap/registration/trajectory_error.hpp"

using mlmap::Pose;

TEST_CASE("trajectoryError: RMS and max of translation and rotation differences") {
  std::vector<Pose> reference(2, Pose::Identity());
  std::vector<Pose> estimate = reference;
  estimate[0].translation() << 0.03, 0.04, 0.0;  // 5 cm
  estimate[1].linear() = Eigen::AngleAxisd(2.0 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const auto error = mlmap::registration::trajectoryError(estimate, reference);
  CHECK(error.poses == 2);
  CHECK(error.max_translation == doctest::Approx(0.05));
  CHECK(error.rms_translation == doctest::Approx(0.05 / std::sqrt(2.0)));
  CHECK(error.max_rotation_deg == doctest::Approx(2.0));
  CHECK(error.rms_rotation_deg == doctest::Approx(std::sqrt(2.0)));
  CHECK_THROWS_AS(mlmap::registration::trajectoryError(estimate, {}), mlmap::Error);
}
