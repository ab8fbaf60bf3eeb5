#include "mlmap/map/surface_points.hpp"

#include <cmath>

namespace mlmap {

std::vector<Point> blockSurfacePoints(const MLMap& blocks, double spacing, SamplePlace place) {
  std::vector<Point> points;
  points.reserve(blocks.blockCount());
  for (std::size_t n = 0; n < blocks.cellCount(); ++n) {
    const Eigen::Vector2d centre = blocks.cellCenter(blocks.cellAt(n));
    for (const Block& block : blocks.blocksAt(n)) {
      Eigen::Vector2d xy = centre;
      if (place == SamplePlace::PointMean && !block.points.empty()) {
        xy += Eigen::Vector2d(block.points.mean_x, block.points.mean_y);
      }
      const auto steps = static_cast<int>(std::floor(block.depth / spacing));
      for (int k = 0; k <= steps; ++k) points.emplace_back(xy.x(), xy.y(), block.height - k * spacing);
    }
  }
  return points;
}

}  // namespace mlmap
