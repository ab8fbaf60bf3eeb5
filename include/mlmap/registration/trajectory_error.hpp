// Absolute trajectory error of estimated poses against reference poses given in the
// same world frame (as registration keeps the first pose where odometry put it, and
// the simulator's odometry starts at the true first pose): no alignment is applied.
#pragma once

#include <cstddef>
#include <vector>

#include "mlmap/scan.hpp"

namespace mlmap::registration {

struct TrajectoryError {
  std::size_t poses = 0;
  double rms_translation = 0.0;    // m
  double max_translation = 0.0;    // m
  double rms_rotation_deg = 0.0;   // deg
  double max_rotation_deg = 0.0;   // deg
};

// Throws mlmap::Error when the two lists differ in length.
TrajectoryError trajectoryError(const std::vector<Pose>& estimate, const std::vector<Pose>& reference);

}  // namespace mlmap::registration
