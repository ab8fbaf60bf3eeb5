// TUM RGB-D trajectory format: "stamp tx ty tz qx qy qz qw", one pose per line.
// A quaternion that is not unit length is normalised (files written with few
// digits are slightly off); a (near-)zero one carries no rotation and is rejected.
#include "mlmap/io/tum_poses.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include "file_bytes.hpp"
#include "mlmap/error.hpp"
#include "number_text.hpp"
#include "text_lines.hpp"

namespace mlmap::io {
namespace {

constexpr std::size_t kFieldsPerPose = 8;
constexpr double kMinQuaternionNorm = 1e-6;

}  // namespace

std::vector<StampedPose> readTumPoses(const std::filesystem::path& path) {
  requireRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open for reading");
  TextLines lines(in, path.string());
  std::vector<StampedPose> poses;
  while (lines.next()) {
    const auto fields = lines.fields(/*hash_comments=*/true);
    if (fields.empty()) continue;
    if (fields.size() != kFieldsPerPose) {
      lines.fail("expected 8 fields (stamp tx ty tz qx qy qz qw), found " +
                 std::to_string(fields.size()));
    }
    double values[kFieldsPerPose];
    for (std::size_t i = 0; i < kFieldsPerPose; ++i) values[i] = lines.parseDouble(fields[i]);
    Eigen::Quaterniond rotation(values[7], values[4], values[5], values[6]);  // w, x, y, z
    const double norm = rotation.norm();
    if (!(norm >= kMinQuaternionNorm)) lines.fail("quaternion (qx qy qz qw) has zero length");
    if (!std::isfinite(norm)) lines.fail("quaternion (qx qy qz qw) is too long to normalise");
    rotation.coeffs() /= norm;
    StampedPose stamped;
    stamped.stamp = values[0];
    stamped.pose = Pose::Identity();
    stamped.pose.linear() = rotation.toRotationMatrix();
    stamped.pose.translation() = Eigen::Vector3d(values[1], values[2], values[3]);
    poses.push_back(stamped);
  }
  if (poses.empty()) {
    throw Error(path.string() + ":" + std::to_string(std::max<std::size_t>(lines.lineNumber(), 1)) +
                ": no poses in file");
  }
  return poses;
}

void writeTumPoses(const std::filesystem::path& path, const std::vector<StampedPose>& poses) {
  std::string text = "# timestamp tx ty tz qx qy qz qw\n";
  for (std::size_t index = 0; index < poses.size(); ++index) {
    const StampedPose& stamped = poses[index];
    Eigen::Quaterniond rotation(stamped.pose.linear());
    const double norm = rotation.norm();
    if (!std::isfinite(stamped.stamp) || !stamped.pose.matrix().allFinite() ||
        !(norm >= kMinQuaternionNorm) || !std::isfinite(norm)) {
      throw Error(path.string() + ": pose " + std::to_string(index) +
                  " is not finite or not a rotation");
    }
    rotation.coeffs() /= norm;
    if (rotation.w() < 0.0) rotation.coeffs() = -rotation.coeffs();  // one sign per rotation
    const Eigen::Vector3d& t = stamped.pose.translation();
    const double values[kFieldsPerPose] = {stamped.stamp, t.x(),        t.y(),        t.z(),
                                           rotation.x(),  rotation.y(), rotation.z(), rotation.w()};
    for (std::size_t i = 0; i < kFieldsPerPose; ++i) {
      if (i > 0) text.push_back(' ');
      appendNumber(text, values[i]);
    }
    text.push_back('\n');
  }
  writeWholeFile(path, text);
}

}  // namespace mlmap::io
