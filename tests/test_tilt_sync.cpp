// Eq. 1–3 and the PTU's trapezoidal profile, against hand-computed cases.
#include <doctest/doctest.h>

#include <cmath>

#include "mlmap/driver/tilt_sync.hpp"

using mlmap::driver::TrapezoidalProfile;

TEST_CASE("Tilt sync: eq. 1 step times and eq. 3 tilt speed") {
  // Step 540 of a 1440-step revolution at 40 Hz: 540 / 57600 s after t_s.
  CHECK(mlmap::driver::stepTime(10.0, 540.0, 40.0, 1440) == doctest::Approx(10.009375));
  CHECK(mlmap::driver::stepTime(10.0, 0.0, 40.0, 1440) == 10.0);
  CHECK(mlmap::driver::tiltSpeedDegS(1.0, 40.0) == doctest::Approx(40.0));
  CHECK(mlmap::driver::tiltSpeedDegS(0.25, 40.0) == doctest::Approx(10.0));
}

TEST_CASE("Tilt sync: trapezoid with a cruise phase") {
  // 0 -> 10°, v = 4°/s, v_b = 1°/s, a = 3°/s²: 1 s ramps covering 2.5° each,
  // 5° at 4°/s in 1.25 s; 3.25 s in all.
  const TrapezoidalProfile profile{0.0, 10.0, 4.0, 1.0, 3.0};
  CHECK(profile.duration() == doctest::Approx(3.25));
  CHECK(profile.peakSpeed() == doctest::Approx(4.0));
  CHECK(profile.angleAt(-1.0) == 0.0);
  CHECK(profile.angleAt(0.5) == doctest::Approx(0.5 + 0.375));  // v_b·l + a·l²/2
  CHECK(profile.angleAt(1.0) == doctest::Approx(2.5));
  CHECK(profile.angleAt(2.0) == doctest::Approx(6.5));
  CHECK(profile.angleAt(3.0) == doctest::Approx(10.0 - (0.25 + 1.5 * 0.0625)));  // mirror image
  CHECK(profile.angleAt(3.25) == doctest::Approx(10.0));
  CHECK(profile.angleAt(99.0) == 10.0);
  // Downwards is the mirror image.
  const TrapezoidalProfile down{10.0, 0.0, 4.0, 1.0, 3.0};
  CHECK(down.angleAt(0.5) == doctest::Approx(10.0 - 0.875));
  CHECK(down.angleAt(2.0) == doctest::Approx(3.5));
}

TEST_CASE("Tilt sync: triangle when the move is too short, instant start below v_b") {
  // 2°: v_peak² = v_b² + a·D = 1 + 6, never reaching 4°/s.
  const TrapezoidalProfile triangle{0.0, 2.0, 4.0, 1.0, 3.0};
  const double peak = std::sqrt(7.0);
  CHECK(triangle.peakSpeed() == doctest::Approx(peak));
  CHECK(triangle.duration() == doctest::Approx(2.0 * (peak - 1.0) / 3.0));
  CHECK(triangle.angleAt(triangle.duration() / 2.0) == doctest::Approx(1.0));
  // v <= v_b: constant speed from the start.
  const TrapezoidalProfile constant{-5.0, 5.0, 2.0, 3.0, 10.0};
  CHECK(constant.duration() == doctest::Approx(5.0));
  CHECK(constant.angleAt(1.0) == doctest::Approx(-3.0));
  // Monotone everywhere.
  const TrapezoidalProfile profile{-30.0, 30.0, 80.0, 5.0, 200.0};
  double last = -31.0;
  for (double l = 0.0; l <= profile.duration() + 0.01; l += 0.001) {
    const double angle = profile.angleAt(l);
    CHECK(angle >= last);
    last = angle;
  }
}
