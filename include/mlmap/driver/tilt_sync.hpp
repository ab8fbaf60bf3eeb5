// Software synchronisation of laser and tilt (section III, eq. 1–3): the time of every
// measurement from its scan's timestamp, and the tilt angle at that time from the
// pan-tilt unit's trapezoidal speed profile.
#pragma once

#include <cstdint>

namespace mlmap::driver {

// eq. 1: time of step p (counted from the scan's first step) of a scan started at t_s,
// the beam turning at f revolutions per second with `steps_per_revolution` steps.
inline double stepTime(double scan_start_s, double step, double revolution_hz,
                       std::uint32_t steps_per_revolution) {
  return scan_start_s + step / (static_cast<double>(steps_per_revolution) * revolution_hz);
}

// eq. 3: tilt speed that advances ρ degrees per laser revolution.
inline double tiltSpeedDegS(double rho_deg, double revolution_hz) { return rho_deg * revolution_hz; }

// The PTU's move from start to end: an instant start at up to the base speed, constant
// acceleration to the commanded speed, cruise, and the mirror image at the end (a
// triangle when the move is too short to reach the commanded speed).
struct TrapezoidalProfile {
  double start_deg = 0.0;
  double end_deg = 0.0;
  double speed_deg_s = 1.0;        // commanded speed v (> 0)
  double base_speed_deg_s = 0.0;   // v_b: reached instantly
  double acceleration_deg_s2 = 0.0;  // used above v_b; 0 means none (v capped at v_b)

  double duration() const;  // s
  // deg, tilt angle l seconds after the move started (eq. 2's l_p): start before it,
  // end after it.
  double angleAt(double l) const;
  double peakSpeed() const;  // deg/s actually reached
};

}  // namespace mlmap::driver
