#include "mlmap/registration/preprocessing.hpp"

#include <cmath>
#include <cstdint>

#include "mlmap/error.hpp"
#include "mlmap/registration/voxel_table.hpp"

namespace mlmap::registration {

std::vector<Point> voxelDownSample(const std::vector<Point>& points, double voxel_size, double min_range,
                                   double max_range) {
  if (!(voxel_size > 0.0)) throw Error("voxel down-sampling: voxel size must be positive");
  // One serial pass: the table numbers voxels in first-seen order, sums[index] is that
  // voxel's running sum, so the output order does not depend on hashing. (Splitting the
  // voxels among threads by key measured twice as slow here: every thread reads every
  // point, and the lookups it saves are few after the last-voxel shortcut.)
  struct Sum {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t count = 0;
  };
  const double inverse_size = 1.0 / voxel_size;
  const double min_sq = min_range * min_range;
  const double max_sq = max_range * max_range;
  VoxelTable table;
  table.reserve(points.size() / 4 + 16);
  std::vector<Sum> sums;
  sums.reserve(points.size() / 4 + 16);
  // Consecutive points of a scan mostly share a voxel: the last one's index saves a lookup.
  VoxelKey last_key{};
  std::uint32_t last_index = VoxelTable::kMissing;
  for (const Point& point : points) {
    const double range_sq = point.squaredNorm();
    if (!point.allFinite() || range_sq < min_sq || range_sq > max_sq) continue;
    const VoxelKey key = voxelKeyOf(point, inverse_size);
    if (last_index == VoxelTable::kMissing || !(key == last_key)) {
      const auto [index, inserted] = table.insert(key);
      if (inserted) sums.emplace_back();
      last_key = key;
      last_index = index;
    }
    sums[last_index].sum += point;
    ++sums[last_index].count;
  }
  std::vector<Point> centroids;
  centroids.reserve(sums.size());
  for (const Sum& sum : sums) centroids.push_back(sum.sum / static_cast<double>(sum.count));
  return centroids;
}

std::vector<Point> cropRange(const std::vector<Point>& points, double min_range, double max_range) {
  std::vector<Point> kept;
  kept.reserve(points.size());
  const double min_sq = min_range * min_range;
  const double max_sq = max_range * max_range;
  for (const Point& point : points) {
    const double range_sq = point.squaredNorm();
    if (range_sq >= min_sq && range_sq <= max_sq) kept.push_back(point);
  }
  return kept;
}

}  // namespace mlmap::registration
