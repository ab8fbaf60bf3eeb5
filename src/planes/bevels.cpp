#include "bevels.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

namespace mlmap {
namespace {

double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(std::abs(a.dot(b)), 0.0, 1.0));
}

// Patches touch within this many cells: blocks at an edge take directions between the two
// surfaces', so neither surface's patch may reach the edge's own column.
constexpr int kTouchCells = 2;
// The sides considered: this many largest patches.
constexpr std::size_t kLargestSides = 32;
// A strip along an edge: at least this share of its blocks touch each of the two surfaces.
constexpr double kTouchingShare = 0.5;
// A piece across a corner: at least this share of its blocks lie on one of the two.
constexpr double kOnNeighboursShare = 0.8;
// Its normal lies between theirs: its angles to the two add up to theirs, within this.
constexpr double kBetweenSlack = 10.0 * std::numbers::pi / 180.0;

}  // namespace

void dropBevels(const BlockGrid& grid, PatchSet& set, double epsilon, double kappa_rad) {
  const std::size_t count = set.planes.size();
  std::vector<bool> drop(count, false);
  std::vector<double> surface(count, 0.0);
  for (std::size_t k = 0; k < count; ++k) surface[k] = surfaceOf(grid, set.blocks[k]);
  // The largest patches by surface: the sides a bevel can have (before the walk that
  // finds which it touches, whether any two of them could hold it between them).
  std::vector<std::size_t> by_surface(count);
  for (std::size_t k = 0; k < count; ++k) by_surface[k] = k;
  std::sort(by_surface.begin(), by_surface.end(), [&](std::size_t a, std::size_t b) { return surface[a] > surface[b]; });
  by_surface.resize(std::min(count, kLargestSides));
  // A bevel has two larger neighbours: the two largest patches are none (nor walked, the
  // floor and the ceiling of a fine map: hundreds of thousands of blocks).
  const double second_largest = count >= 2 ? surface[by_surface[1]] : std::numeric_limits<double>::infinity();
  const auto between = [&](const Eigen::Vector3d& normal, const Eigen::Vector3d& first, const Eigen::Vector3d& second) {
    const double apart = angleBetween(first, second);
    return apart >= std::numbers::pi / 4.0 && angleBetween(normal, first) >= 0.5 * kappa_rad &&
           angleBetween(normal, second) >= 0.5 * kappa_rad &&
           angleBetween(normal, first) + angleBetween(normal, second) <= apart + kBetweenSlack;
  };
  for (std::size_t k = 0; k < count; ++k) {
    const std::vector<std::uint32_t>& blocks = set.blocks[k];
    if (blocks.empty() || surface[k] >= second_largest) continue;
    bool possible = false;
    for (std::size_t a = 0; a < by_surface.size() && !possible; ++a)
      for (std::size_t b = a + 1; b < by_surface.size() && !possible; ++b)
        possible = surface[by_surface[b]] > surface[k] &&
                   between(set.planes[k].normal, set.planes[by_surface[a]].normal, set.planes[by_surface[b]].normal);
    if (!possible) continue;
    // Per neighbouring patch, how many of this patch's blocks touch it.
    std::map<std::int32_t, std::size_t> touching;
    for (const std::uint32_t id : blocks) {
      std::vector<std::int32_t> seen;
      grid.forEachNeighbour(grid.blocks()[id].cell, kTouchCells, [&](std::uint32_t other) {
        const std::int32_t label = set.labels[other];
        if (label > 0 && static_cast<std::size_t>(label) != k + 1 &&
            std::find(seen.begin(), seen.end(), label) == seen.end())
          seen.push_back(label);
      });
      for (const std::int32_t label : seen) ++touching[label];
    }
    const Eigen::Vector3d& normal = set.planes[k].normal;
    // Larger patches it touches (in surface: a wall's column is one block), at least κ/2
    // from it in direction.
    std::vector<std::pair<std::size_t, std::size_t>> sides;  // (patch, blocks touching it)
    for (const auto& [label, blocks_touching] : touching) {
      const auto other = static_cast<std::size_t>(label - 1);
      if (surface[other] > surface[k] && angleBetween(normal, set.planes[other].normal) >= 0.5 * kappa_rad)
        sides.emplace_back(other, blocks_touching);
    }
    // The share of its blocks lying on one of two planes (within ε): a piece across a
    // corner is made of the two walls' blocks; a surface of its own across the corner (a
    // corner cabinet's front) lies off both.
    const auto onEither = [&](const Plane& first, const Plane& second) {
      std::size_t on = 0;
      for (const std::uint32_t id : blocks) {
        const Eigen::Vector3d point = grid.blocks()[id].point.cast<double>();
        const double a = std::abs(first.normal.dot(point) + first.offset);
        const double b = std::abs(second.normal.dot(point) + second.offset);
        on += std::min(a, b) <= epsilon ? 1 : 0;
      }
      return static_cast<double>(on) / static_cast<double>(blocks.size());
    };
    for (std::size_t a = 0; a < sides.size() && !drop[k]; ++a) {
      for (std::size_t b = a + 1; b < sides.size() && !drop[k]; ++b) {
        const Plane& first = set.planes[sides[a].first];
        const Plane& second = set.planes[sides[b].first];
        const double apart = angleBetween(first.normal, second.normal);
        if (apart < std::numbers::pi / 4.0 ||
            angleBetween(normal, first.normal) + angleBetween(normal, second.normal) > apart + kBetweenSlack)
          continue;
        const double share = kTouchingShare * static_cast<double>(blocks.size());
        const bool strip = static_cast<double>(sides[a].second) >= share && static_cast<double>(sides[b].second) >= share;
        drop[k] = strip || onEither(first, second) >= kOnNeighboursShare;
      }
    }
  }
  dropPatches(set, drop);
}

}  // namespace mlmap
