#include "mlmap/io/transform_file.hpp"

#include <cmath>
#include <numbers>
#include <sstream>
#include <vector>

#include "file_bytes.hpp"
#include "mlmap/error.hpp"
#include "number_text.hpp"
#include "text_lines.hpp"

namespace mlmap::io {

Pose parseTransform(std::string_view text, const std::string& name) {
  std::istringstream stream{std::string(text)};
  TextLines lines(stream, name);
  std::vector<double> numbers;
  while (lines.next()) {
    for (const std::string_view field : lines.fields(true)) {
      if (numbers.size() == 16) lines.fail("more than 16 numbers");
      numbers.push_back(lines.parseDouble(field));
    }
  }
  Pose pose = Pose::Identity();
  switch (numbers.size()) {
    case 4:
      pose.linear() = Eigen::AngleAxisd(numbers[3] * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ())
                          .toRotationMatrix();
      pose.translation() = Eigen::Vector3d(numbers[0], numbers[1], numbers[2]);
      return pose;
    case 7: {
      const Eigen::Quaterniond rotation(numbers[6], numbers[3], numbers[4], numbers[5]);
      if (std::abs(rotation.norm() - 1.0) > 1e-3) throw Error(name + ": the quaternion is not a unit quaternion");
      pose.linear() = rotation.normalized().toRotationMatrix();
      pose.translation() = Eigen::Vector3d(numbers[0], numbers[1], numbers[2]);
      return pose;
    }
    case 16: {
      Eigen::Matrix4d matrix;
      for (int row = 0; row < 4; ++row) {
        for (int column = 0; column < 4; ++column) matrix(row, column) = numbers[static_cast<std::size_t>(row * 4 + column)];
      }
      const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
      if (!matrix.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1), 1e-9) ||
          !(rotation * rotation.transpose()).isIdentity(1e-3) || rotation.determinant() < 0.0) {
        throw Error(name + ": the matrix is not a rigid transform (rotation not orthonormal, or last row not 0 0 0 1)");
      }
      // Re-orthonormalise what a text round trip left slightly off.
      const Eigen::Quaterniond quaternion(rotation);
      pose.linear() = quaternion.normalized().toRotationMatrix();
      pose.translation() = matrix.topRightCorner<3, 1>();
      return pose;
    }
    default:
      throw Error(name + ": expected 4 (x y z yaw_deg), 7 (x y z qx qy qz qw) or 16 (4 x 4 matrix) numbers, found " +
                  std::to_string(numbers.size()));
  }
}

Pose readTransform(const std::filesystem::path& path) { return parseTransform(readWholeFile(path), path.string()); }

void writeTransform(const std::filesystem::path& path, const Pose& pose) {
  std::string out = "# mlmap transform: 4 x 4 matrix, row by row (other -> base)\n";
  const Eigen::Matrix4d matrix = pose.matrix();
  for (int row = 0; row < 4; ++row) {
    for (int column = 0; column < 4; ++column) {
      if (column > 0) out += ' ';
      appendNumber(out, matrix(row, column));
    }
    out += '\n';
  }
  writeWholeFile(path, out);
}

}  // namespace mlmap::io
