#include "mlmap/registration/preprocessing.hpp"

#include <cmath>
#include <cstdint>

#include "mlmap/error.hpp"
#include "mlmap/registration/voxel_table.hpp"

namespace mlmap::registration {

namespace {

// Voxels are split by key into this many partitions, each summed by one thread: a fixed
// number, not one per thread, so the result is the same at any thread count.
constexpr std::size_t kPartitions = 4;
constexpr std::uint8_t kSkipped = 0xff;  // a point outside the range, or not finite

std::uint8_t partitionOf(const VoxelKey& key) {
  const std::uint64_t mixed = static_cast<std::uint64_t>(static_cast<std::uint32_t>(key.x)) * 2654435761u ^
                              static_cast<std::uint64_t>(static_cast<std::uint32_t>(key.y)) * 2246822519u ^
                              static_cast<std::uint64_t>(static_cast<std::uint32_t>(key.z)) * 3266489917u;
  return static_cast<std::uint8_t>((mixed >> 16) % kPartitions);
}

}  // namespace

std::vector<Point> voxelDownSample(const std::vector<Point>& points, double voxel_size, double min_range,
                                   double max_range) {
  if (!(voxel_size > 0.0)) throw Error("voxel down-sampling: voxel size must be positive");
  const double inverse_size = 1.0 / voxel_size;
  const double min_sq = min_range * min_range;
  const double max_sq = max_range * max_range;
  const long count = static_cast<long>(points.size());
  std::vector<VoxelKey> keys(points.size());
  std::vector<std::uint8_t> partition(points.size());
  // Serial: a millisecond of arithmetic, less than a fork-join on a busy machine.
  for (long i = 0; i < count; ++i) {
    const Point& point = points[static_cast<std::size_t>(i)];
    const double range_sq = point.squaredNorm();
    if (!point.allFinite() || range_sq < min_sq || range_sq > max_sq) {
      partition[static_cast<std::size_t>(i)] = kSkipped;
      continue;
    }
    keys[static_cast<std::size_t>(i)] = voxelKeyOf(point, inverse_size);
    partition[static_cast<std::size_t>(i)] = partitionOf(keys[static_cast<std::size_t>(i)]);
  }

  // Each partition sums its voxels' points in input order (as one serial pass would) and
  // numbers its voxels; `first` marks each voxel's first point with that number, which
  // gives the output its first-seen order.
  struct Sum {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t count = 0;
  };
  struct Part {
    VoxelTable table;
    std::vector<Sum> sums;
  };
  std::vector<Part> parts(kPartitions);
  std::vector<std::uint32_t> first(points.size(), VoxelTable::kMissing);
#pragma omp parallel for schedule(dynamic, 1)
  for (long p = 0; p < static_cast<long>(kPartitions); ++p) {
    Part& part = parts[static_cast<std::size_t>(p)];
    part.table.reserve(points.size() / (4 * kPartitions) + 16);
    // Consecutive points of a scan mostly share a voxel: the last one's index saves a lookup.
    VoxelKey last_key{};
    std::uint32_t last_index = VoxelTable::kMissing;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (partition[i] != p) continue;
      if (last_index == VoxelTable::kMissing || !(keys[i] == last_key)) {
        const auto [index, inserted] = part.table.insert(keys[i]);
        if (inserted) {
          part.sums.emplace_back();
          first[i] = index;
        }
        last_key = keys[i];
        last_index = index;
      }
      part.sums[last_index].sum += points[i];
      ++part.sums[last_index].count;
    }
  }
  std::size_t voxels = 0;
  for (const Part& part : parts) voxels += part.sums.size();
  std::vector<Point> centroids;
  centroids.reserve(voxels);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (first[i] == VoxelTable::kMissing) continue;
    const Sum& sum = parts[partition[i]].sums[first[i]];
    centroids.push_back(sum.sum / static_cast<double>(sum.count));
  }
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
