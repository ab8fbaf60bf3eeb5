#include "sheets.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "id_set.hpp"

namespace mlmap {
namespace {

std::size_t rootOf(std::vector<std::uint32_t>& parent, std::size_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

std::vector<std::vector<std::uint32_t>> sheetsOf(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                                 const CandidatePlane& plane, double step, int radius,
                                                 double max_rise) {
  if (blocks.empty()) return {};
  IdSet members(grid.size());
  for (const std::uint32_t id : blocks) members.insert(id);
  // A vertical block is a segment from its bottom to its top; its distance from a plane
  // that is not upright changes along it. Two blocks are compared where they are
  // closest: at one height where their spans overlap, else at their facing ends (at
  // mid-height a plane tilted between two faces, one above the other, would put both
  // faces' blocks at one distance).
  struct Span {
    float level;   // m, the distance from the plane at height 0 (point minus its z part)
    float bottom;  // m, heights
    float top;
  };
  std::vector<Span> spans(blocks.size());
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const PlaneBlock& block = grid.blocks()[blocks[k]];
    const float distance = plane.normal.dot(block.point - plane.point);
    const float low = block.vertical ? block.bottom : block.point.z();
    const float high = block.vertical ? block.top : block.point.z();
    spans[k] = {distance - plane.normal.z() * block.point.z(), low, high};
  }
  // Blocks further apart in height than max_rise (a wall's foot and the top of the face
  // behind it, 1.5 m up in the cell beside it) are not neighbours on any surface:
  // infinitely different. Over such a rise the plane's tilt made fr079's 7 cm step look
  // like 5, where a candidate leaning between two faces fitted both.
  const auto reach = static_cast<float>(max_rise);
  const auto difference = [&spans, &plane, reach](std::size_t a, std::size_t b) {
    const Span& first = spans[a];
    const Span& second = spans[b];
    float dz = 0.0F;  // the height of b's closest point minus a's
    if (second.bottom > first.top) dz = second.bottom - first.top;
    if (first.bottom > second.top) dz = second.top - first.bottom;
    if (std::abs(dz) > reach) return std::numeric_limits<float>::infinity();
    return std::abs(second.level - first.level + plane.normal.z() * dz);
  };
  std::vector<std::uint32_t> parent(blocks.size());
  std::iota(parent.begin(), parent.end(), 0U);
  const auto indexOf = [&blocks](std::uint32_t id) {
    return static_cast<std::size_t>(std::lower_bound(blocks.begin(), blocks.end(), id) - blocks.begin());
  };
  // Each pair once, from its lower id.
  const auto forEachPair = [&](auto&& visit) {
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      const std::uint32_t id = blocks[k];
      grid.forEachNeighbour(grid.blocks()[id].cell, radius, [&](std::uint32_t other) {
        if (other > id && members.contains(other)) visit(k, indexOf(other));
      });
    }
  };
  forEachPair([&](std::size_t k, std::size_t n) {
    if (difference(k, n) > step) return;
    const std::size_t a = rootOf(parent, k);
    const std::size_t b = rootOf(parent, n);
    if (a != b) parent[std::max(a, b)] = static_cast<std::uint32_t>(std::min(a, b));
  });
  std::vector<std::int64_t> sheet_of_root(blocks.size(), -1);
  std::vector<std::vector<std::uint32_t>> sheets;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const std::size_t root = rootOf(parent, k);
    if (sheet_of_root[root] < 0) {
      sheet_of_root[root] = static_cast<std::int64_t>(sheets.size());
      sheets.emplace_back();
    }
    sheets[static_cast<std::size_t>(sheet_of_root[root])].push_back(blocks[k]);
  }
  return sheets;
}

}  // namespace mlmap
