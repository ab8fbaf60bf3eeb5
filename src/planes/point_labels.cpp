#include "mlmap/planes/point_labels.hpp"

#include <cmath>
#include <limits>

namespace mlmap {

std::vector<std::int32_t> labelPoints(const MLMap& map, const Scan& scan) {
  std::vector<std::int32_t> labels(scan.size(), -1);
  const double reach = map.cellSize();
  const auto count = static_cast<std::int64_t>(scan.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < count; ++k) {
    const auto index = static_cast<std::size_t>(k);
    const Point p = scan.worldPoint(index);
    // Points without a cell get no label (cellOf would throw inside the parallel loop).
    const auto cell = map.findCellOf(p.x(), p.y());
    if (!cell || !std::isfinite(p.z())) continue;
    double best = std::numeric_limits<double>::infinity();
    for (const Block& block : map.blocks(*cell)) {
      const double distance = p.z() > block.height ? p.z() - block.height
                              : p.z() < block.bottom() ? block.bottom() - p.z()
                                                       : 0.0;
      if (distance < reach && distance < best) {
        best = distance;
        labels[index] = block.plane;
      }
    }
  }
  return labels;
}

}  // namespace mlmap
