#include "unseen_gaps.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numeric>

namespace mlmap {
namespace {

struct Extent {
  double low = 0.0;   // m, along the wall
  double high = 0.0;
};

Extent extentAlong(const BlockGrid& grid, const Patch& patch, const Eigen::Vector3d& u_axis,
                   const Eigen::Vector3d& point) {
  Extent extent{1e300, -1e300};
  for (const std::uint32_t id : patch.blocks) {
    const double u = u_axis.dot(grid.blocks()[id].point.cast<double>() - point);
    extent.low = std::min(extent.low, u);
    extent.high = std::max(extent.high, u);
  }
  return extent;
}

// Whether the map holds blocks on both sides of the wall between u_low and u_high:
// what the scanner saw through an opening (the near side always has the floor).
bool seenThrough(const BlockGrid& grid, const Eigen::Vector3d& normal, const Eigen::Vector3d& u_axis,
                 const Eigen::Vector3d& point, double u_low, double u_high, double epsilon, double reach) {
  const double cell = grid.cellSize();
  const Eigen::Vector3d a = point + u_axis * u_low;
  const Eigen::Vector3d b = point + u_axis * u_high;
  const auto index = [cell](double coordinate) { return static_cast<std::int64_t>(std::floor(coordinate / cell)); };
  bool front = false;
  bool behind = false;
  grid.forEachInCells(index(std::min(a.y(), b.y()) - reach), index(std::max(a.y(), b.y()) + reach),
                      index(std::min(a.x(), b.x()) - reach), index(std::max(a.x(), b.x()) + reach),
                      [&](std::uint32_t id) {
                        const Eigen::Vector3d offset = grid.blocks()[id].point.cast<double>() - point;
                        const double u = u_axis.dot(offset);
                        const double distance = normal.dot(offset);
                        if (u <= u_low || u >= u_high || std::abs(distance) < epsilon || std::abs(distance) > reach) {
                          return;
                        }
                        (distance > 0.0 ? front : behind) = true;
                      });
  return front && behind;
}

}  // namespace

void joinUnseenGaps(const BlockGrid& grid, std::vector<Patch>& patches, const Eigen::Vector3d& normal,
                    const Eigen::Vector3d& point, double epsilon, double reach) {
  if (patches.size() < 2 || std::abs(normal.z()) >= 0.2) return;
  Eigen::Vector3d u_axis;
  Eigen::Vector3d v_axis;
  planeBasis(normal, u_axis, v_axis);
  std::vector<Extent> extents;
  extents.reserve(patches.size());
  for (const Patch& patch : patches) extents.push_back(extentAlong(grid, patch, u_axis, point));
  std::vector<std::size_t> order(patches.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return extents[a].low < extents[b].low; });
  // Along the wall, each piece joins the run before it when a gap of more than a cell
  // separates them and nothing was seen through it. Pieces beside each other along
  // the wall (one above the other) are separate: their gap is not along the wall.
  std::vector<Patch> joined;
  double run_high = 0.0;
  for (const std::size_t k : order) {
    const Extent& extent = extents[k];
    const bool gap = !joined.empty() && extent.low > run_high + grid.cellSize();
    if (gap && !seenThrough(grid, normal, u_axis, point, run_high, extent.low, epsilon, reach)) {
      Patch& run = joined.back();
      std::vector<std::uint32_t> blocks;
      blocks.reserve(run.blocks.size() + patches[k].blocks.size());
      std::merge(run.blocks.begin(), run.blocks.end(), patches[k].blocks.begin(), patches[k].blocks.end(),
                 std::back_inserter(blocks));
      run.blocks = std::move(blocks);
      run.surface += patches[k].surface;
      run_high = std::max(run_high, extent.high);
      continue;
    }
    joined.push_back(std::move(patches[k]));
    run_high = extent.high;
  }
  if (joined.size() == patches.size()) {
    // Nothing joined: the pieces moved out in u order; put them back as they came.
    for (std::size_t n = 0; n < order.size(); ++n) patches[order[n]] = std::move(joined[n]);
    return;
  }
  std::stable_sort(joined.begin(), joined.end(), [](const Patch& a, const Patch& b) { return a.surface > b.surface; });
  patches = std::move(joined);
}

}  // namespace mlmap
