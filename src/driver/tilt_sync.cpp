#include "mlmap/driver/tilt_sync.hpp"

#include <algorithm>
#include <cmath>

namespace mlmap::driver {
namespace {

struct Phases {
  double accel_s = 0.0;   // time spent accelerating (and decelerating, each)
  double cruise_s = 0.0;
  double peak = 0.0;      // deg/s
  double start_speed = 0.0;
};

Phases phases(const TrapezoidalProfile& profile) {
  const double distance = std::abs(profile.end_deg - profile.start_deg);
  Phases result;
  const double v = std::max(profile.speed_deg_s, 1e-9);
  const double vb = std::max(profile.base_speed_deg_s, 0.0);
  const double a = profile.acceleration_deg_s2;
  if (v <= vb || a <= 0.0) {  // instant start at v (capped at v_b without acceleration)
    result.peak = a <= 0.0 && vb > 0.0 ? std::min(v, vb) : v;
    result.start_speed = result.peak;
    result.cruise_s = distance / result.peak;
    return result;
  }
  result.start_speed = vb;
  double accel_s = (v - vb) / a;
  double accel_distance = vb * accel_s + 0.5 * a * accel_s * accel_s;
  if (2.0 * accel_distance <= distance) {
    result.peak = v;
    result.accel_s = accel_s;
    result.cruise_s = (distance - 2.0 * accel_distance) / v;
  } else {  // triangle: v_peak² = v_b² + a·D
    result.peak = std::sqrt(vb * vb + a * distance);
    result.accel_s = (result.peak - vb) / a;
  }
  return result;
}

}  // namespace

double TrapezoidalProfile::duration() const {
  const Phases p = phases(*this);
  return 2.0 * p.accel_s + p.cruise_s;
}

double TrapezoidalProfile::peakSpeed() const { return phases(*this).peak; }

double TrapezoidalProfile::angleAt(double l) const {
  const Phases p = phases(*this);
  const double distance = std::abs(end_deg - start_deg);
  const double sign = end_deg >= start_deg ? 1.0 : -1.0;
  const double total = 2.0 * p.accel_s + p.cruise_s;
  const double a = acceleration_deg_s2;
  double covered;
  if (l <= 0.0) {
    covered = 0.0;
  } else if (l >= total) {
    covered = distance;
  } else if (l < p.accel_s) {
    covered = p.start_speed * l + 0.5 * a * l * l;
  } else if (l <= p.accel_s + p.cruise_s) {
    const double accel_distance = p.start_speed * p.accel_s + 0.5 * a * p.accel_s * p.accel_s;
    covered = accel_distance + p.peak * (l - p.accel_s);
  } else {
    const double left = total - l;
    covered = distance - (p.start_speed * left + 0.5 * a * left * left);
  }
  return start_deg + sign * std::clamp(covered, 0.0, distance);
}

}  // namespace mlmap::driver
