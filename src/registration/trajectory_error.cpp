#include "mlmap/registration/trajectory_error.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "mlmap/error.hpp"

namespace mlmap::registration {

TrajectoryError trajectoryError(const std::vector<Pose>& estimate, const std::vector<Pose>& reference) {
  if (estimate.size() != reference.size()) {
    throw Error("trajectory error: " + std::to_string(estimate.size()) + " estimated poses for " +
                std::to_string(reference.size()) + " reference poses");
  }
  TrajectoryError error;
  error.poses = estimate.size();
  if (estimate.empty()) return error;
  double sum_translation_sq = 0.0;
  double sum_rotation_sq = 0.0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const double translation = (estimate[i].translation() - reference[i].translation()).norm();
    const double rotation_deg =
        Eigen::AngleAxisd(reference[i].linear().transpose() * estimate[i].linear()).angle() * 180.0 /
        std::numbers::pi;
    sum_translation_sq += translation * translation;
    sum_rotation_sq += rotation_deg * rotation_deg;
    error.max_translation = std::max(error.max_translation, translation);
    error.max_rotation_deg = std::max(error.max_rotation_deg, rotation_deg);
  }
  const double n = static_cast<double>(estimate.size());
  error.rms_translation = std::sqrt(sum_translation_sq / n);
  error.rms_rotation_deg = std::sqrt(sum_rotation_sq / n);
  return error;
}

}  // namespace mlmap::registration
