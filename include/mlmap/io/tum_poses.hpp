// Pose lists in TUM format: "stamp tx ty tz qx qy qz qw" per line, '#' comments.
// One pose per scan, in order.
#pragma once

#include <filesystem>
#include <vector>

#include "mlmap/scan.hpp"

namespace mlmap::io {

struct StampedPose {
  double stamp = 0.0;
  Pose pose = Pose::Identity();
};

std::vector<StampedPose> readTumPoses(const std::filesystem::path& path);

// Stamps are written with full precision; quaternions normalised, qw >= 0.
void writeTumPoses(const std::filesystem::path& path, const std::vector<StampedPose>& poses);

}  // namespace mlmap::io
