// 3DTK / slam6D "uos" scans: scanNNN.3d holds "x y z" per line in centimetres in
// 3DTK's left-handed frame (x right, y up, z forward); scanNNN.pose holds the
// position (cm) and then three Euler angles (degrees).
//
// 3DTK's pose convention (slam6D, globals.icc EulerToMatrix4; the .pose reader
// converts the angles from degrees to radians first): the scan's world matrix is
//     R_L = Rx(θx) · Ry(θy) · Rz(θz),   t_L = (tx, ty, tz),
// with the usual rotation matrices Rx, Ry, Rz written out on 3DTK's own
// coordinate numbers (stored column-major, OpenGL style), and a point maps to the
// world as w_L = R_L · p_L + t_L.
//
// mlmap's frame is right-handed, z up, x forward, metres. The axis change is
//     p_r = A · p_L / 100,   A = [ 0 0 1 ; -1 0 0 ; 0 1 0 ]   (x_r = z, y_r = -x, z_r = y).
// det A = -1, which is exactly the handedness flip. Applying A to both sides of
// the world map gives w_r = A R_L Aᵀ · p_r + A t_L / 100, so
//     R_r = A · R_L · Aᵀ   (a proper rotation again: det = det(A)² · det R_L = 1),
//     t_r = A · t_L / 100.
// Writing inverts this: R_L = Aᵀ R_r A, t_L = 100 Aᵀ t_r, and the Euler angles come
// from R_L = Rx Ry Rz (see eulerXyz). A positive 3DTK θy, a turn about 3DTK's up
// axis, is a negative yaw about mlmap's z: A flips the sense of rotation.
//
// Checked on 3DTK's own example scans (tests/test_threedtk.cpp): floors come out
// level in the world frame and consecutive scans overlap.
#include "mlmap/io/threedtk.hpp"

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

constexpr double kCentimetresPerMetre = 100.0;
constexpr double kPi = 3.14159265358979323846;

// 3DTK (left-handed, y up, z forward) -> mlmap (right-handed, z up, x forward).
Eigen::Matrix3d axisChange() {
  Eigen::Matrix3d a;
  // clang-format off
  a << 0, 0, 1,
      -1, 0, 0,
       0, 1, 0;
  // clang-format on
  return a;
}

// The old "uos" header, e.g. "360 x 225" (scan lines x points per line).
bool isOldHeader(const std::vector<std::string_view>& fields) {
  if (fields.size() != 3 || fields[1] != "x") return false;
  for (const auto field : {fields[0], fields[2]}) {
    if (field.empty() ||
        !std::all_of(field.begin(), field.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      return false;
    }
  }
  return true;
}

// 3DTK reads the six numbers with operator>>, so any layout is accepted as long as
// there are exactly six; the usual one is "tx ty tz" then "rx ry rz".
Pose readPoseFile(const std::filesystem::path& path) {
  std::ifstream in = openForReading(path);
  TextLines lines(in, path.string());
  std::vector<double> values;
  while (lines.next()) {
    for (const auto field : lines.fields()) {
      if (values.size() == 6)
        lines.fail("more than 6 numbers (tx ty tz in cm, rx ry rz in degrees)");
      values.push_back(lines.parseDouble(field));
    }
  }
  if (values.size() != 6) {
    lines.fail("expected 6 numbers (tx ty tz in cm, rx ry rz in degrees), found " +
               std::to_string(values.size()));
  }
  const double to_radians = kPi / 180.0;
  const Eigen::Matrix3d rotation_3dtk =
      (Eigen::AngleAxisd(values[3] * to_radians, Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(values[4] * to_radians, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(values[5] * to_radians, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  const Eigen::Vector3d translation_3dtk(values[0], values[1], values[2]);
  const Eigen::Matrix3d a = axisChange();
  Pose pose = Pose::Identity();
  pose.linear() = a * rotation_3dtk * a.transpose();
  pose.translation() = a * translation_3dtk / kCentimetresPerMetre;
  return pose;
}

// Euler angles (radians) of R = Rx(θx) Ry(θy) Rz(θz). θz is taken from
// cx·R(1,0) + sx·R(2,0) = sin θz and cx·R(1,1) + sx·R(2,1) = cos θz, which stay
// exact near gimbal lock (θy = ±90°, i.e. a yaw of ±90° in mlmap's frame, a common
// pose), where the two small entries that give θx lose their precision.
Eigen::Vector3d eulerXyz(const Eigen::Matrix3d& r) {
  const double theta_y = std::atan2(r(0, 2), std::hypot(r(0, 0), r(0, 1)));
  const double theta_x = std::atan2(-r(1, 2), r(2, 2));  // 0 at exact gimbal lock
  const double sx = std::sin(theta_x), cx = std::cos(theta_x);
  const double theta_z = std::atan2(cx * r(1, 0) + sx * r(2, 0), cx * r(1, 1) + sx * r(2, 1));
  return {theta_x, theta_y, theta_z};
}

void appendTriple(std::string& buffer, const Eigen::Vector3d& values) {
  appendNumber(buffer, values.x());
  buffer.push_back(' ');
  appendNumber(buffer, values.y());
  buffer.push_back(' ');
  appendNumber(buffer, values.z());
  buffer.push_back('\n');
}

}  // namespace

Scan readThreeDtkScan(const std::filesystem::path& path) {
  std::ifstream in = openForReading(path);
  std::filesystem::path pose_path = path;
  pose_path.replace_extension(".pose");

  Scan scan;
  scan.pose = readPoseFile(pose_path);  // first: a missing .pose fails before parsing the points
  const Eigen::Matrix3d to_metres = axisChange() / kCentimetresPerMetre;
  TextLines lines(in, path.string());
  while (lines.next()) {
    const auto fields = lines.fields();
    if (fields.empty()) continue;
    if (lines.lineNumber() == 1 && isOldHeader(fields)) continue;
    if (fields.size() < 3) {
      lines.fail("expected at least 3 fields (x y z in cm), found " +
                 std::to_string(fields.size()));
    }
    // Columns after x y z (reflectance, colour in the uos_r/uos_rgb variants) are ignored.
    const Eigen::Vector3d point_3dtk(lines.parseDouble(fields[0]), lines.parseDouble(fields[1]),
                                     lines.parseDouble(fields[2]));
    scan.points.push_back(to_metres * point_3dtk);
  }
  if (scan.points.empty()) {
    throw Error(path.string() + ":" + std::to_string(std::max<std::size_t>(lines.lineNumber(), 1)) +
                ": no points in file");
  }
  return scan;
}

void writeThreeDtkScan(const std::filesystem::path& path, const Scan& scan) {
  if (!scan.pose.matrix().allFinite()) throw Error(path.string() + ": pose is not finite");
  const Eigen::Matrix3d a = axisChange();
  const Eigen::Matrix3d to_centimetres = a.transpose() * kCentimetresPerMetre;

  std::string points_text;
  points_text.reserve(scan.points.size() * 40);
  for (std::size_t index = 0; index < scan.points.size(); ++index) {
    if (!scan.points[index].allFinite()) {
      throw Error(path.string() + ": point " + std::to_string(index) + " is not finite");
    }
    appendTriple(points_text, to_centimetres * scan.points[index]);
  }

  const Eigen::Matrix3d rotation_3dtk = a.transpose() * scan.pose.linear() * a;
  std::string pose_text;
  appendTriple(pose_text, to_centimetres * scan.pose.translation());
  appendTriple(pose_text, eulerXyz(rotation_3dtk) * (180.0 / kPi));

  std::filesystem::path pose_path = path;
  pose_path.replace_extension(".pose");
  // The scan first: a .pose without its .3d is never read, a .3d without a .pose is refused.
  writeWholeFile(path, points_text);
  writeWholeFile(pose_path, pose_text);
}

}  // namespace mlmap::io
