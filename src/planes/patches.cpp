#include "mlmap/planes/patches.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>

namespace mlmap {
namespace {

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

// Blocks rasterised on a grid of cell_size in the plane: a dense raster over their
// bounding box with a margin (planes in a building are compact, and lookups in an
// array beat a hash map by far). Raster cell (u, v) covers [u, u + 1) × [v, v + 1) cells
// along the plane basis from `point`.
struct PlaneRaster {
  std::int32_t min_u = 0;
  std::int32_t min_v = 0;
  std::int64_t columns = 0;
  std::int64_t rows = 0;
  int margin = 0;
  std::vector<std::int32_t> slots;         // per raster cell: its number among the occupied ones, −1 empty
  std::vector<Eigen::Vector2i> cells;      // occupied cells, in order of first use
  std::vector<std::size_t> first_of_block; // a block's cells in block_cells: [first_of_block[k], first_of_block[k + 1])
  std::vector<std::size_t> block_cells;    // occupied-cell numbers

  std::int32_t& at(std::int64_t u, std::int64_t v) {
    return slots[static_cast<std::size_t>((v - min_v + margin) * columns + (u - min_u + margin))];
  }

  PlaneRaster(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& u_axis,
              const Eigen::Vector3d& v_axis, const Eigen::Vector3d& point, int margin_cells)
      : margin(margin_cells) {
    const double cell = grid.cellSize();
    std::vector<Eigen::Vector2i> raw;
    first_of_block.resize(blocks.size() + 1);
    auto cellOf = [&](const Eigen::Vector3d& p) {
      const Eigen::Vector3d relative = p - point;
      return Eigen::Vector2i(static_cast<std::int32_t>(std::floor(relative.dot(u_axis) / cell)),
                             static_cast<std::int32_t>(std::floor(relative.dot(v_axis) / cell)));
    };
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      first_of_block[k] = raw.size();
      const PlaneBlock& block = grid.blocks()[blocks[k]];
      const Eigen::Vector3d centre = block.point.cast<double>();
      raw.push_back(cellOf(centre));
      if (!block.vertical) continue;
      const double depth = block.top - block.bottom;
      const int steps = std::max(1, static_cast<int>(std::ceil(depth / cell)));
      for (int s = 0; s <= steps; ++s) {
        raw.push_back(cellOf(Eigen::Vector3d(centre.x(), centre.y(), block.bottom + depth * s / steps)));
      }
    }
    first_of_block[blocks.size()] = raw.size();
    if (raw.empty()) return;
    min_u = raw[0].x();
    min_v = raw[0].y();
    std::int32_t max_u = min_u;
    std::int32_t max_v = min_v;
    for (const Eigen::Vector2i& c : raw) {
      min_u = std::min(min_u, c.x());
      max_u = std::max(max_u, c.x());
      min_v = std::min(min_v, c.y());
      max_v = std::max(max_v, c.y());
    }
    columns = static_cast<std::int64_t>(max_u) - min_u + 1 + 2 * margin;
    rows = static_cast<std::int64_t>(max_v) - min_v + 1 + 2 * margin;
    slots.assign(static_cast<std::size_t>(columns * rows), -1);
    block_cells.resize(raw.size());
    for (std::size_t n = 0; n < raw.size(); ++n) {
      std::int32_t& slot = at(raw[n].x(), raw[n].y());
      if (slot < 0) {
        slot = static_cast<std::int32_t>(cells.size());
        cells.push_back(raw[n]);
      }
      block_cells[n] = static_cast<std::size_t>(slot);
    }
  }
};

// The outer boundary of the occupied cells accepted by `inside`: the sides of those
// cells facing other cells, chained into counter-clockwise loops; the loop enclosing
// the most area, corners only.
template <typename Inside>
std::vector<Eigen::Vector2i> outerBoundary(PlaneRaster& raster, Inside&& inside) {
  // Vertices of the raster with a margin of one: each has at most two outgoing edges.
  const std::int64_t vertex_columns = raster.columns + 1;
  auto vertexOf = [&](std::int64_t u, std::int64_t v) {
    return static_cast<std::size_t>((v - raster.min_v + raster.margin) * vertex_columns + (u - raster.min_u + raster.margin));
  };
  std::vector<std::array<std::int32_t, 2>> out(static_cast<std::size_t>(vertex_columns * (raster.rows + 1)), {-1, -1});
  std::vector<Eigen::Vector2i> edge_from;
  std::vector<Eigen::Vector2i> edge_to;
  auto occupied = [&](std::int64_t u, std::int64_t v) {
    if (u < raster.min_u - raster.margin || v < raster.min_v - raster.margin ||
        u >= raster.min_u - raster.margin + raster.columns || v >= raster.min_v - raster.margin + raster.rows) {
      return false;
    }
    const std::int32_t slot = raster.at(u, v);
    return slot >= 0 && inside(static_cast<std::size_t>(slot));
  };
  auto addEdge = [&](const Eigen::Vector2i& from, const Eigen::Vector2i& to) {
    auto& slots = out[vertexOf(from.x(), from.y())];
    (slots[0] < 0 ? slots[0] : slots[1]) = static_cast<std::int32_t>(edge_from.size());
    edge_from.push_back(from);
    edge_to.push_back(to);
  };
  for (std::size_t n = 0; n < raster.cells.size(); ++n) {
    if (!inside(n)) continue;
    const int u = raster.cells[n].x();
    const int v = raster.cells[n].y();
    if (!occupied(u, v - 1)) addEdge({u, v}, {u + 1, v});
    if (!occupied(u + 1, v)) addEdge({u + 1, v}, {u + 1, v + 1});
    if (!occupied(u, v + 1)) addEdge({u + 1, v + 1}, {u, v + 1});
    if (!occupied(u - 1, v)) addEdge({u, v + 1}, {u, v});
  }
  std::vector<std::uint8_t> used(edge_from.size(), 0);
  std::vector<Eigen::Vector2i> best;
  long best_area = 0;
  for (std::size_t start = 0; start < edge_from.size(); ++start) {
    if (used[start] != 0) continue;
    std::vector<Eigen::Vector2i> loop;
    std::int32_t edge = static_cast<std::int32_t>(start);
    while (edge >= 0 && used[static_cast<std::size_t>(edge)] == 0) {
      used[static_cast<std::size_t>(edge)] = 1;
      loop.push_back(edge_from[static_cast<std::size_t>(edge)]);
      const Eigen::Vector2i& to = edge_to[static_cast<std::size_t>(edge)];
      const auto& next = out[vertexOf(to.x(), to.y())];
      edge = next[0] >= 0 && used[static_cast<std::size_t>(next[0])] == 0 ? next[0] : next[1];
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

void planeBasis(const Eigen::Vector3d& normal, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  u = Eigen::Vector3d::UnitZ().cross(normal);
  if (u.norm() < 0.3) u = normal.cross(Eigen::Vector3d::UnitX()).cross(normal);
  u.normalize();
  v = normal.cross(u).normalized();
}

std::vector<Patch> splitIntoPatches(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                    const Eigen::Vector3d& normal, const Eigen::Vector3d& point,
                                    int gap_cells) {
  if (blocks.empty()) return {};
  Eigen::Vector3d u_axis;
  Eigen::Vector3d v_axis;
  planeBasis(normal, u_axis, v_axis);
  PlaneRaster raster(grid, blocks, u_axis, v_axis, point, gap_cells);
  DisjointSets sets(raster.cells.size());
  for (std::size_t n = 0; n < raster.cells.size(); ++n) {
    // Half the neighbourhood suffices: the other half links back to this cell.
    for (int dv = 0; dv <= gap_cells; ++dv) {
      for (int du = -gap_cells; du <= gap_cells; ++du) {
        if (dv == 0 && du <= 0) continue;
        const std::int32_t other = raster.at(raster.cells[n].x() + du, raster.cells[n].y() + dv);
        if (other >= 0) sets.unite(n, static_cast<std::size_t>(other));
      }
    }
  }
  // Components keyed by their root; roots are the smallest cell number, so the
  // order is deterministic.
  std::map<std::size_t, Patch> by_root;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    Patch& patch = by_root[sets.find(raster.block_cells[raster.first_of_block[k]])];
    patch.blocks.push_back(blocks[k]);
    patch.surface += grid.blocks()[blocks[k]].surface;
  }
  std::vector<Patch> patches;
  for (auto& [root, patch] : by_root) patches.push_back(std::move(patch));
  std::stable_sort(patches.begin(), patches.end(),
                   [](const Patch& a, const Patch& b) { return a.surface > b.surface; });
  return patches;
}

std::vector<Eigen::Vector3d> outlineOf(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                       const Eigen::Vector3d& normal, const Eigen::Vector3d& point) {
  std::vector<Eigen::Vector3d> outline;
  if (blocks.empty()) return outline;
  Eigen::Vector3d u_axis;
  Eigen::Vector3d v_axis;
  planeBasis(normal, u_axis, v_axis);
  PlaneRaster raster(grid, blocks, u_axis, v_axis, point, 1);
  const double cell = grid.cellSize();
  for (const Eigen::Vector2i& corner : outerBoundary(raster, [](std::size_t) { return true; })) {
    outline.push_back(point + u_axis * (corner.x() * cell) + v_axis * (corner.y() * cell));
  }
  return outline;
}

}  // namespace mlmap
