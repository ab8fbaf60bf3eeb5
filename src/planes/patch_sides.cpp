#include "patch_sides.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "label_fits.hpp"

namespace mlmap {
namespace {

// Along a stretch of the edge a patch's points "do not reach" a side of the other's plane
// where at most this share of them there (on its own plane) lie beyond that plane's σ:
// room for the corner's noise tail (a stretch holds the patch's points across its whole
// width, those within a σ or two of the edge a few percent of them) and the odd point of
// the other surface; and they lie on the other side where half of them lie past it there.
constexpr double kStrayShare = 0.01;
constexpr double kBodyShare = 0.5;
// Fewer points than this on a stretch tell nothing.
constexpr std::size_t kMinStretchPoints = 3;

// The side of a plane that a stretch's points stay off (+1: none but strays above, half or
// more below; -1 the mirror), else 0.
int sideOff(std::size_t above, std::size_t below, std::size_t all) {
  if (all < kMinStretchPoints) return 0;
  const auto share = [all](std::size_t c) { return static_cast<double>(c) / static_cast<double>(all); };
  if (share(above) <= kStrayShare && share(below) >= kBodyShare) return 1;
  if (share(below) <= kStrayShare && share(above) >= kBodyShare) return -1;
  return 0;
}

}  // namespace

PatchSides::PatchSides(std::span<const Point> points, std::span<const std::uint32_t> slot_of_point,
                       const std::vector<PointPlane>& fitted, const OutlineReach& outline, double parallel_cosine,
                       double cell, double sigmas)
    : stretch_(cell) {
  const std::size_t slots = fitted.size();
  // Each patch's sampled points that lie on its own plane (within its tolerance); none
  // where the slots are not given (a cloud without scanners).
  std::vector<std::vector<Point>> on_plane(slots);
  forSampledPoints(slot_of_point.first(std::min(points.size(), slot_of_point.size())), slots, kPatchSample,
                   [&](std::size_t index, std::uint32_t slot) {
                     const PointPlane& plane = fitted[slot];
                     const double distance = plane.normal.dot(points[index]) + plane.offset;
                     if (std::abs(distance) <= plane.tolerance) on_plane[slot].push_back(points[index]);  // NaN fails
                   });
  const std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs = outline.pairs();
  std::vector<Edge> edges(pairs.size());
  const auto total = static_cast<std::int64_t>(pairs.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (std::int64_t k = 0; k < total; ++k) {
    const auto [a, b] = pairs[static_cast<std::size_t>(k)];
    if (a >= slots || b >= slots || on_plane[a].empty() || !(cell > 0.0) || !(sigmas > 0.0)) continue;
    const PointPlane& edge = fitted[b];
    if (std::abs(edge.normal.dot(fitted[a].normal)) >= parallel_cosine) continue;
    // The outline first: it stays within b's tolerance and a cell's diagonal on one side
    // of the plane (its vertices are the corners of cells holding points within that
    // tolerance) and reaches beyond that on the other. A wall's top under the ceiling,
    // seen elsewhere down to the floor, does; but so does a table top reaching 8-13 cm past
    // a panel under it at 10 cm cells (PCL's office1), which its points tell apart.
    const auto extent = outline.of(a, b);
    if (!extent) continue;
    const double margin = std::sqrt(2.0) * cell + edge.tolerance;
    const int outline_side = extent->second <= margin && extent->first < -margin   ? 1
                             : extent->first >= -margin && extent->second > margin ? -1
                                                                                    : 0;
    if (outline_side == 0) continue;
    // Then the points, stretch by stretch along the edge: a door lets a ceiling through a
    // wall's plane in one place (PCL's room_scan2: 1.2 % of its points), and a shelf hides
    // a wall below it in another.
    Edge& out = edges[static_cast<std::size_t>(k)];
    out.along = fitted[a].normal.cross(edge.normal).normalized();
    double low = std::numeric_limits<double>::infinity(), high = -low;
    for (const Point& p : on_plane[a]) {
      low = std::min(low, out.along.dot(p));
      high = std::max(high, out.along.dot(p));
    }
    const auto stretches = static_cast<std::size_t>(std::floor((high - low) / cell)) + 1;
    out.start = low;
    const double sigma = edge.tolerance / sigmas;
    std::vector<std::size_t> above(stretches, 0), below(stretches, 0), all(stretches, 0);
    for (const Point& p : on_plane[a]) {
      const auto at = std::min(stretches - 1, static_cast<std::size_t>((out.along.dot(p) - low) / cell));
      const double distance = edge.normal.dot(p) + edge.offset;
      ++all[at];
      above[at] += distance > sigma ? 1 : 0;
      below[at] += distance < -sigma ? 1 : 0;
    }
    out.side.assign(stretches, 0);
    for (std::size_t s = 0; s < stretches; ++s)
      if (sideOff(above[s], below[s], all[s]) == outline_side) out.side[s] = static_cast<std::int8_t>(outline_side);
  }
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (std::any_of(edges[k].side.begin(), edges[k].side.end(), [](std::int8_t s) { return s != 0; }))
      edges_.emplace(pairKey(pairs[k].first, pairs[k].second), std::move(edges[k]));
}

int PatchSides::endsAt(std::uint32_t a, std::uint32_t b, const Point& at) const {
  const auto found = edges_.find(pairKey(a, b));
  if (found == edges_.end()) return 0;
  const Edge& edge = found->second;
  const double position = (edge.along.dot(at) - edge.start) / stretch_;
  if (!(position >= 0.0) || position >= static_cast<double>(edge.side.size())) return 0;
  return edge.side[static_cast<std::size_t>(position)];
}

}  // namespace mlmap
