#include "mlmap/registration/preprocessing.hpp"

#include <cmath>
#include <unordered_map>

#include "mlmap/error.hpp"

namespace mlmap::registration {

std::vector<Point> voxelDownSample(const std::vector<Point>& points, double voxel_size) {
  if (!(voxel_size > 0.0)) throw Error("voxel down-sampling: voxel size must be positive");
  struct Sum {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t count = 0;
    std::size_t order = 0;
  };
  // Integer voxel coordinates like OcTree keys, but without their ±32768 range limit.
  struct Key {
    long x, y, z;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& key) const {
      return static_cast<std::size_t>(key.x) * 73856093u ^ static_cast<std::size_t>(key.y) * 19349663u ^
             static_cast<std::size_t>(key.z) * 83492791u;
    }
  };
  const double factor = 1.0 / voxel_size;
  std::unordered_map<Key, Sum, KeyHash> voxels;
  voxels.reserve(points.size() / 4 + 1);
  for (const Point& point : points) {
    if (!point.allFinite()) continue;
    const Key key{static_cast<long>(std::floor(point.x() * factor)),
                  static_cast<long>(std::floor(point.y() * factor)),
                  static_cast<long>(std::floor(point.z() * factor))};
    auto [it, inserted] = voxels.try_emplace(key);
    if (inserted) it->second.order = voxels.size() - 1;
    it->second.sum += point;
    ++it->second.count;
  }
  std::vector<Point> centroids(voxels.size());
  for (const auto& [key, sum] : voxels) centroids[sum.order] = sum.sum / static_cast<double>(sum.count);
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
