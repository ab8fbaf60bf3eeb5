#include "surface_noise.hpp"

#include <cmath>

#include "median.hpp"

namespace mlmap {

std::optional<double> surfaceNoise(const MLMap& map, const std::vector<Plane>& planes, std::size_t min_blocks) {
  std::vector<const Plane*> by_id;
  for (const Plane& plane : planes) {
    if (plane.id <= 0) continue;
    if (static_cast<std::size_t>(plane.id) >= by_id.size()) by_id.resize(static_cast<std::size_t>(plane.id) + 1, nullptr);
    by_id[static_cast<std::size_t>(plane.id)] = &plane;
  }
  std::vector<float> distances;
  for (std::size_t n = 0; n < map.cellCount(); ++n) {
    const Eigen::Vector2d centre = map.cellCenter(map.cellAt(n));
    for (const Block& block : map.blocksAt(n)) {
      if (block.plane <= 0 || static_cast<std::size_t>(block.plane) >= by_id.size() || block.points.empty()) continue;
      const Plane* plane = by_id[static_cast<std::size_t>(block.plane)];
      if (plane == nullptr) continue;
      const PointStats& points = block.points;
      const Eigen::Vector3d mean(centre.x() + points.mean_x, centre.y() + points.mean_y, points.mean_z);
      const double along = plane->normal.dot(mean) + plane->offset;
      const double count = points.count;
      // The scatter's share, unbiased: one degree of freedom went into the mean.
      const double across = count > 1.0 ? plane->normal.dot(points.scatterMatrix() * plane->normal) / (count - 1.0) : 0.0;
      distances.push_back(static_cast<float>(std::sqrt(along * along + std::max(0.0, across))));
    }
  }
  if (distances.size() < min_blocks) return std::nullopt;
  return medianOf(distances);
}

}  // namespace mlmap
