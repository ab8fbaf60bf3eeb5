#include "seen_gaps.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <unordered_map>

namespace mlmap {
namespace {

std::int64_t keyOf(CellIndex cell) {
  return (static_cast<std::int64_t>(cell.i) << 32) ^ static_cast<std::uint32_t>(cell.j);
}

int chebyshev(CellIndex a, CellIndex b) { return std::max(std::abs(a.i - b.i), std::abs(a.j - b.j)); }

}  // namespace

double heightAt(const BlockGrid& grid, const Eigen::Vector3d& normal, const Eigen::Vector3d& point, CellIndex cell) {
  const Eigen::Vector2d centre = grid.cellCentre(cell);
  return point.z() - (normal.x() * (centre.x() - point.x()) + normal.y() * (centre.y() - point.y())) / normal.z();
}

bool seenPast(const BlockGrid& grid, const Eigen::Vector3d& normal, const Eigen::Vector3d& point, CellIndex from,
              CellIndex to, double tolerance, FarSide far_side) {
  return anyCellBetween(from, to, [&](CellIndex cell) {
    const double height = heightAt(grid, normal, point, cell);
    bool beyond = false, at = false;
    grid.forEachInCells(cell.i, cell.i, cell.j, cell.j, [&](std::uint32_t id) {
      const PlaneBlock& block = grid.blocks()[id];
      if (far_side == FarSide::Below ? block.top < height - tolerance : block.bottom > height + tolerance) {
        beyond = true;
      } else if (far_side == FarSide::Below ? block.bottom <= height + tolerance : block.top >= height - tolerance) {
        at = true;
      }
    });
    return beyond && !at;
  });
}

namespace {

// Of the blocks' cells, how many hold map surface above the plane, and how many below.
struct Beyond {
  std::size_t above = 0;
  std::size_t below = 0;
};

Beyond beyond(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
              const Eigen::Vector3d& point, double tolerance) {
  Beyond counts;
  for (const std::uint32_t id : blocks) {
    const CellIndex cell = grid.blocks()[id].cell;
    const double height = heightAt(grid, normal, point, cell);
    bool above = false, below = false;
    grid.forEachInCells(cell.i, cell.i, cell.j, cell.j, [&](std::uint32_t other) {
      above = above || grid.blocks()[other].bottom > height + tolerance;
      below = below || grid.blocks()[other].top < height - tolerance;
    });
    counts.above += above ? 1 : 0;
    counts.below += below ? 1 : 0;
  }
  return counts;
}

}  // namespace

bool seenFromAbove(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
                   const Eigen::Vector3d& point, double tolerance) {
  return 2 * beyond(grid, blocks, normal, point, tolerance).above > blocks.size();
}

void splitAtSeenGaps(const BlockGrid& grid, std::vector<Patch>& patches, std::vector<std::vector<Segment>>& outline_runs,
                     const Eigen::Vector3d& normal, const Eigen::Vector3d& point, double tolerance) {
  if (std::abs(normal.z()) < std::cos(std::numbers::pi / 4.0)) return;
  std::vector<Patch> result;
  std::vector<std::vector<Segment>> result_runs;
  bool cut = false;
  for (std::size_t k = 0; k < patches.size(); ++k) {
    const std::vector<std::uint32_t>& blocks = patches[k].blocks;
    // Nothing seen under the plane in its own cells (a floor): nothing to see past.
    const Beyond counts = beyond(grid, blocks, normal, point, tolerance);
    if (2 * counts.above <= blocks.size() || counts.below == 0) {
      result.push_back(std::move(patches[k]));
      result_runs.push_back(std::move(outline_runs[k]));
      continue;
    }
    std::unordered_map<std::int64_t, std::vector<std::uint32_t>> at_cell;  // positions in `blocks`
    for (std::uint32_t n = 0; n < blocks.size(); ++n) at_cell[keyOf(grid.blocks()[blocks[n]].cell)].push_back(n);
    std::vector<std::uint32_t> parent(blocks.size());
    std::iota(parent.begin(), parent.end(), 0U);
    const auto root = [&](std::uint32_t n) {
      while (parent[n] != n) n = parent[n] = parent[parent[n]];
      return n;
    };
    // Cell to cell first: the gaps are judged between the pieces that result.
    for (const int reach : {1, 2}) {
      for (std::uint32_t n = 0; n < blocks.size(); ++n) {
        const CellIndex cell = grid.blocks()[blocks[n]].cell;
        for (int di = -reach; di <= reach; ++di) {
          for (int dj = -reach; dj <= reach; ++dj) {
            const CellIndex near{cell.i + di, cell.j + dj};
            if (chebyshev(cell, near) != reach) continue;
            const auto found = at_cell.find(keyOf(near));
            if (found == at_cell.end()) continue;
            for (const std::uint32_t m : found->second) {
              if (root(m) == root(n)) continue;
              if (reach == 1 || !seenPast(grid, normal, point, cell, near, tolerance)) parent[root(m)] = root(n);
            }
          }
        }
      }
    }
    std::unordered_map<std::uint32_t, std::size_t> piece_of_root;
    std::vector<Patch> pieces;
    for (std::uint32_t n = 0; n < blocks.size(); ++n) {
      const auto [slot, added] = piece_of_root.try_emplace(root(n), pieces.size());
      if (added) pieces.emplace_back();
      Patch& piece = pieces[slot->second];
      piece.blocks.push_back(blocks[n]);  // ascending, as the patch's
      piece.surface += grid.blocks()[blocks[n]].surface;
    }
    if (pieces.size() <= 1) {
      result.push_back(std::move(patches[k]));
      result_runs.push_back(std::move(outline_runs[k]));
      continue;
    }
    cut = true;
    for (Patch& piece : pieces) {
      result.push_back(std::move(piece));
      result_runs.emplace_back();
    }
  }
  if (!cut) {  // as they were, in their order
    patches = std::move(result);
    outline_runs = std::move(result_runs);
    return;
  }
  std::vector<std::size_t> order(result.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return result[a].surface > result[b].surface; });
  patches.clear();
  outline_runs.clear();
  for (const std::size_t k : order) {
    patches.push_back(std::move(result[k]));
    outline_runs.push_back(std::move(result_runs[k]));
  }
}

}  // namespace mlmap
