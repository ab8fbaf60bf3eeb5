#include "mlmap/io/isolated_points.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "kept_readings.hpp"

namespace mlmap::io {
namespace {

// A reading's cube of side `radius`, as three integers packed into one key (21 bits
// each: ±10⁶ cubes, ±100 km at 0.1 m; beyond that cubes alias, which only costs time).
std::uint64_t cubeKey(std::int64_t x, std::int64_t y, std::int64_t z) {
  constexpr std::uint64_t kMask = (std::uint64_t{1} << 21) - 1;
  return (static_cast<std::uint64_t>(x) & kMask) | ((static_cast<std::uint64_t>(y) & kMask) << 21) |
         ((static_cast<std::uint64_t>(z) & kMask) << 42);
}

}  // namespace

std::size_t dropIsolated(Scan& scan, const IsolationFilter& filter) {
  if (!filter.enabled() || scan.size() == 0) return 0;
  const double inverse = 1.0 / filter.radius;
  const double radius_squared = filter.radius * filter.radius;
  const std::size_t count = scan.size();
  // The readings sorted by cube, and each cube's run of them.
  std::vector<std::int64_t> cells(3 * count);
  std::vector<std::uint64_t> keys(count);
  std::vector<std::uint32_t> order(count);
  for (std::size_t k = 0; k < count; ++k) {
    for (int axis = 0; axis < 3; ++axis) {
      const double scaled = scan.points[k][axis] * inverse;
      cells[3 * k + static_cast<std::size_t>(axis)] =
          std::isfinite(scaled) ? static_cast<std::int64_t>(std::floor(std::clamp(scaled, -1e15, 1e15))) : 0;
    }
    keys[k] = cubeKey(cells[3 * k], cells[3 * k + 1], cells[3 * k + 2]);
    order[k] = static_cast<std::uint32_t>(k);
  }
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
  std::unordered_map<std::uint64_t, std::pair<std::uint32_t, std::uint32_t>> runs;  // key -> [begin, end) in order
  runs.reserve(count);
  for (std::size_t begin = 0; begin < count;) {
    std::size_t end = begin + 1;
    while (end < count && keys[order[end]] == keys[order[begin]]) ++end;
    runs.emplace(keys[order[begin]], std::make_pair(static_cast<std::uint32_t>(begin), static_cast<std::uint32_t>(end)));
    begin = end;
  }
  const auto needed = static_cast<std::size_t>(filter.min_neighbours);
  std::vector<char> keep(count, 0);
  for (std::size_t k = 0; k < count; ++k) {
    const Point& point = scan.points[k];
    if (!point.allFinite()) continue;
    std::size_t neighbours = 0;
    for (std::int64_t dx = -1; dx <= 1 && neighbours < needed; ++dx) {
      for (std::int64_t dy = -1; dy <= 1 && neighbours < needed; ++dy) {
        for (std::int64_t dz = -1; dz <= 1 && neighbours < needed; ++dz) {
          const auto run = runs.find(cubeKey(cells[3 * k] + dx, cells[3 * k + 1] + dy, cells[3 * k + 2] + dz));
          if (run == runs.end()) continue;
          for (std::uint32_t n = run->second.first; n < run->second.second && neighbours < needed; ++n) {
            const std::uint32_t other = order[n];
            if (other != k && (scan.points[other] - point).squaredNorm() <= radius_squared) ++neighbours;
          }
        }
      }
    }
    keep[k] = neighbours >= needed ? 1 : 0;
  }
  return keepReadings(scan, [&](std::size_t k) { return keep[k] != 0; });
}

}  // namespace mlmap::io
