#include "mlmap/map/point_stats.hpp"

#include <Eigen/Geometry>

namespace mlmap {

Eigen::Matrix3d PointStats::scatterMatrix() const {
  Eigen::Matrix3d m;
  m << scatter[0], scatter[1], scatter[2], scatter[1], scatter[3], scatter[4], scatter[2], scatter[4], scatter[5];
  return m;
}

void PointStats::add(float x, float y, float z) {
  ++count;
  const float inverse = 1.0F / static_cast<float>(count);
  const float dx = x - mean_x;
  const float dy = y - mean_y;
  const float dz = z - mean_z;
  mean_x += dx * inverse;
  mean_y += dy * inverse;
  mean_z += dz * inverse;
  // (p − old mean)(p − new mean)ᵀ is symmetric in expectation; its xy and yx terms
  // differ by rounding only, so one of each pair is kept.
  const float ex = x - mean_x;
  const float ey = y - mean_y;
  const float ez = z - mean_z;
  scatter[0] += dx * ex;
  scatter[1] += dx * ey;
  scatter[2] += dx * ez;
  scatter[3] += dy * ey;
  scatter[4] += dy * ez;
  scatter[5] += dz * ez;
}

void PointStats::merge(const PointStats& other) {
  if (other.count == 0) return;
  if (count == 0) {
    *this = other;
    return;
  }
  const double n_a = count;
  const double n_b = other.count;
  const double n = n_a + n_b;
  const double dx = static_cast<double>(other.mean_x) - mean_x;
  const double dy = static_cast<double>(other.mean_y) - mean_y;
  const double dz = static_cast<double>(other.mean_z) - mean_z;
  const double weight = n_a * n_b / n;
  const double deltas[6] = {dx * dx, dx * dy, dx * dz, dy * dy, dy * dz, dz * dz};
  for (int k = 0; k < 6; ++k) {
    scatter[k] = static_cast<float>(static_cast<double>(scatter[k]) + other.scatter[k] + weight * deltas[k]);
  }
  mean_x = static_cast<float>(mean_x + dx * n_b / n);
  mean_y = static_cast<float>(mean_y + dy * n_b / n);
  mean_z = static_cast<float>(mean_z + dz * n_b / n);
  count += other.count;
}

PointStats PointStats::shifted(double shift_x, double shift_y) const {
  PointStats moved = *this;
  moved.mean_x = static_cast<float>(mean_x - shift_x);
  moved.mean_y = static_cast<float>(mean_y - shift_y);
  return moved;
}

PointStats PointStats::turned(double yaw, double dz) const {
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  PointStats moved = *this;
  const Eigen::Vector3d mean_turned = rotation * mean();
  moved.mean_x = static_cast<float>(mean_turned.x());
  moved.mean_y = static_cast<float>(mean_turned.y());
  moved.mean_z = static_cast<float>(mean_turned.z() + dz);
  const Eigen::Matrix3d scatter_turned = rotation * scatterMatrix() * rotation.transpose();
  const int rows[6] = {0, 0, 0, 1, 1, 2};
  const int cols[6] = {0, 1, 2, 1, 2, 2};
  for (int k = 0; k < 6; ++k) moved.scatter[k] = static_cast<float>(scatter_turned(rows[k], cols[k]));
  return moved;
}

void PointMoments::add(const PointStats& stats, const Eigen::Vector3d& centre) {
  if (stats.count == 0) return;
  const double n = stats.count;
  const Eigen::Vector3d mean = centre + stats.mean();
  count += n;
  sum += n * mean;
  outer += stats.scatterMatrix() + n * mean * mean.transpose();
}

}  // namespace mlmap
