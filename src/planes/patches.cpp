#include "mlmap/planes/patches.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_map>

namespace mlmap {
namespace {

struct GridCell {
  std::int32_t u = 0;
  std::int32_t v = 0;
  friend bool operator==(const GridCell&, const GridCell&) = default;
};

struct GridCellHash {
  std::size_t operator()(const GridCell& cell) const {
    return (static_cast<std::size_t>(static_cast<std::uint32_t>(cell.u)) * 0x9E3779B97F4A7C15ULL) ^
           static_cast<std::uint32_t>(cell.v);
  }
};

class DisjointSets {
 public:
  explicit DisjointSets(std::size_t count) : parent_(count) {
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }
  std::size_t find(std::size_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void unite(std::size_t a, std::size_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<std::size_t> parent_;
};

}  // namespace

void planeBasis(const Eigen::Vector3d& normal, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  u = Eigen::Vector3d::UnitZ().cross(normal);
  if (u.norm() < 0.3) u = normal.cross(Eigen::Vector3d::UnitX()).cross(normal);
  u.normalize();
  v = normal.cross(u).normalized();
}

namespace {

// The outer boundary of a set of grid cells: the sides of occupied cells facing
// empty ones, chained into loops; the loop enclosing the most area is the outline.
std::vector<Eigen::Vector2i> outerBoundary(const std::vector<GridCell>& cells) {
  std::unordered_map<GridCell, bool, GridCellHash> occupied;
  for (const GridCell& cell : cells) occupied[cell] = true;
  auto isOccupied = [&](std::int32_t u, std::int32_t v) { return occupied.count(GridCell{u, v}) > 0; };
  // Directed edges with the cells on their left: counter-clockwise loops.
  std::multimap<std::pair<int, int>, std::pair<int, int>> next;
  for (const GridCell& c : cells) {
    if (!isOccupied(c.u, c.v - 1)) next.emplace(std::pair{c.u, c.v}, std::pair{c.u + 1, c.v});
    if (!isOccupied(c.u + 1, c.v)) next.emplace(std::pair{c.u + 1, c.v}, std::pair{c.u + 1, c.v + 1});
    if (!isOccupied(c.u, c.v + 1)) next.emplace(std::pair{c.u + 1, c.v + 1}, std::pair{c.u, c.v + 1});
    if (!isOccupied(c.u - 1, c.v)) next.emplace(std::pair{c.u, c.v + 1}, std::pair{c.u, c.v});
  }
  std::vector<Eigen::Vector2i> best;
  long best_area = 0;
  while (!next.empty()) {
    std::vector<Eigen::Vector2i> loop;
    auto edge = next.begin();
    const std::pair<int, int> start = edge->first;
    std::pair<int, int> at = start;
    while (true) {
      auto found = next.find(at);
      if (found == next.end()) break;
      loop.emplace_back(at.first, at.second);
      at = found->second;
      next.erase(found);
      if (at == start) break;
    }
    long twice_area = 0;
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const auto& a = loop[k];
      const auto& b = loop[(k + 1) % loop.size()];
      twice_area += static_cast<long>(a.x()) * b.y() - static_cast<long>(b.x()) * a.y();
    }
    if (twice_area > best_area) {
      best_area = twice_area;
      best = std::move(loop);
    }
  }
  // Keep corners only.
  std::vector<Eigen::Vector2i> corners;
  for (std::size_t k = 0; k < best.size(); ++k) {
    const Eigen::Vector2i& previous = best[(k + best.size() - 1) % best.size()];
    const Eigen::Vector2i& next_point = best[(k + 1) % best.size()];
    const Eigen::Vector2i a = best[k] - previous;
    const Eigen::Vector2i b = next_point - best[k];
    if (a.x() * b.y() - a.y() * b.x() != 0) corners.push_back(best[k]);
  }
  return corners;
}

}  // namespace

std::vector<Patch> splitIntoPatches(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                    const Eigen::Vector3d& normal, const Eigen::Vector3d& point,
                                    int gap_cells) {
  if (blocks.empty()) return {};
  Eigen::Vector3d u_axis;
  Eigen::Vector3d v_axis;
  planeBasis(normal, u_axis, v_axis);
  const double cell = grid.cellSize();
  // Every block's grid cells on the plane (a vertical block covers its height).
  std::vector<GridCell> block_cells;
  std::vector<std::size_t> first_cell_of_block(blocks.size() + 1);
  auto cellOf = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d relative = p - point;
    return GridCell{static_cast<std::int32_t>(std::floor(relative.dot(u_axis) / cell)),
                    static_cast<std::int32_t>(std::floor(relative.dot(v_axis) / cell))};
  };
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    first_cell_of_block[k] = block_cells.size();
    const PlaneBlock& block = grid.blocks()[blocks[k]];
    const Eigen::Vector3d centre = block.point.cast<double>();
    block_cells.push_back(cellOf(centre));
    if (!block.vertical) continue;
    const double depth = block.top - block.bottom;
    const int steps = std::max(1, static_cast<int>(std::ceil(depth / cell)));
    for (int s = 0; s <= steps; ++s) {
      block_cells.push_back(cellOf(Eigen::Vector3d(centre.x(), centre.y(), block.bottom + depth * s / steps)));
    }
  }
  first_cell_of_block[blocks.size()] = block_cells.size();
  // A dense raster over the cells' bounding box (with a margin for the gap): planes
  // in a building are compact, and lookups in an array beat a hash map by far.
  std::int32_t min_u = block_cells[0].u, max_u = min_u, min_v = block_cells[0].v, max_v = min_v;
  for (const GridCell& c : block_cells) {
    min_u = std::min(min_u, c.u);
    max_u = std::max(max_u, c.u);
    min_v = std::min(min_v, c.v);
    max_v = std::max(max_v, c.v);
  }
  const std::int64_t columns = static_cast<std::int64_t>(max_u) - min_u + 1 + 2 * gap_cells;
  const std::int64_t rows = static_cast<std::int64_t>(max_v) - min_v + 1 + 2 * gap_cells;
  std::vector<std::int32_t> raster(static_cast<std::size_t>(columns * rows), -1);
  auto at = [&](std::int64_t u, std::int64_t v) -> std::int32_t& {
    return raster[static_cast<std::size_t>((v - min_v + gap_cells) * columns + (u - min_u + gap_cells))];
  };
  std::vector<GridCell> cells;  // distinct occupied cells
  std::vector<std::size_t> cell_of(block_cells.size());
  for (std::size_t n = 0; n < block_cells.size(); ++n) {
    std::int32_t& slot = at(block_cells[n].u, block_cells[n].v);
    if (slot < 0) {
      slot = static_cast<std::int32_t>(cells.size());
      cells.push_back(block_cells[n]);
    }
    cell_of[n] = static_cast<std::size_t>(slot);
  }
  DisjointSets sets(cells.size());
  for (std::size_t n = 0; n < cells.size(); ++n) {
    // Half the neighbourhood suffices: the other half links back to this cell.
    for (int dv = 0; dv <= gap_cells; ++dv) {
      for (int du = -gap_cells; du <= gap_cells; ++du) {
        if (dv == 0 && du <= 0) continue;
        const std::int32_t other = at(cells[n].u + du, cells[n].v + dv);
        if (other >= 0) sets.unite(n, static_cast<std::size_t>(other));
      }
    }
  }
  // Components keyed by their root; roots are the smallest cell number, so the
  // order is deterministic.
  std::map<std::size_t, Patch> by_root;
  std::map<std::size_t, std::vector<GridCell>> cells_by_root;
  for (std::size_t n = 0; n < cells.size(); ++n) cells_by_root[sets.find(n)].push_back(cells[n]);
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    Patch& patch = by_root[sets.find(cell_of[first_cell_of_block[k]])];
    patch.blocks.push_back(blocks[k]);
    patch.surface += grid.blocks()[blocks[k]].surface;
  }
  std::vector<Patch> patches;
  for (auto& [root, patch] : by_root) {
    for (const Eigen::Vector2i& corner : outerBoundary(cells_by_root[root])) {
      patch.outline.push_back(point + u_axis * (corner.x() * cell) + v_axis * (corner.y() * cell));
    }
    patches.push_back(std::move(patch));
  }
  std::stable_sort(patches.begin(), patches.end(),
                   [](const Patch& a, const Patch& b) { return a.surface > b.surface; });
  return patches;
}

}  // namespace mlmap
