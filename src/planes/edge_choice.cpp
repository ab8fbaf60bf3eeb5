#include "edge_choice.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace mlmap {
namespace {

// A patch's heights in bins of this (or its tolerance).
constexpr double kHeightBin = 0.02;

// Height bins of one patch at most (2 km at 2 cm).
constexpr double kMaxHeightBins = 1e5;

// σ of a normal distribution from the median of its absolute values.
constexpr double kMadToSigma = 1.4826;

}  // namespace

std::vector<double> alongTolerances(std::span<const Point> points, std::span<const std::uint32_t> slot_of_point,
                                    const std::vector<PointPlane>& fitted,
                                    const std::function<Eigen::Vector3d(std::size_t)>& beam_of, double sigmas) {
  const std::size_t slots = fitted.size();
  std::vector<double> tolerance(slots, std::numeric_limits<double>::infinity());
  std::vector<std::vector<float>> offsets(slots);
  for (std::size_t index = 0; index < points.size(); ++index) {
    const std::uint32_t slot = slot_of_point[index];
    if (slot == 0) continue;
    const PointPlane& plane = fitted[slot];
    const double signed_distance = plane.normal.dot(points[index]) + plane.offset;
    const double along = plane.normal.dot(beam_of(index));
    if (!(std::abs(signed_distance) <= plane.tolerance) || !(std::abs(along) >= kMinIncidenceCosine)) continue;
    offsets[slot].push_back(static_cast<float>(std::abs(signed_distance / along)));
  }
  for (std::size_t slot = 1; slot < slots; ++slot) {
    std::vector<float>& o = offsets[slot];
    if (o.size() < 3) continue;
    std::nth_element(o.begin(), o.begin() + static_cast<std::ptrdiff_t>(o.size() / 2), o.end());
    tolerance[slot] = std::max(fitted[slot].tolerance, sigmas * kMadToSigma * o[o.size() / 2]);
  }
  return tolerance;
}

std::vector<HeightRange> patchHeights(std::span<const Point> points, std::span<const std::uint32_t> sole,
                                      const std::vector<PointPlane>& fitted, double min_width) {
  const std::size_t slots = fitted.size();
  struct Bin {  // how far along the patch (horizontally) a bin's points lie
    float low = std::numeric_limits<float>::infinity();
    float high = -std::numeric_limits<float>::infinity();
  };
  std::vector<std::vector<Bin>> bins(slots);
  std::vector<float> base(slots, std::numeric_limits<float>::infinity());
  std::vector<Eigen::Vector3d> across(slots, Eigen::Vector3d::UnitX());
  for (std::size_t slot = 1; slot < slots; ++slot) {
    const Eigen::Vector3d horizontal = fitted[slot].normal.cross(Eigen::Vector3d::UnitZ());
    if (horizontal.norm() > 0.1) across[slot] = horizontal.normalized();
  }
  // Along the patch from its first point: the spans are kept in float, which far from the
  // origin (a national grid's coordinates, 5,000 km) rounds by half a metre.
  std::vector<Eigen::Vector3d> first_point(slots, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (std::size_t index = 0; index < points.size(); ++index)
    if (sole[index] != 0 && std::isfinite(points[index].z()))
      base[sole[index]] = std::min(base[sole[index]], static_cast<float>(points[index].z()));
  const auto binWidth = [&](std::size_t slot) { return std::max(kHeightBin, fitted[slot].tolerance); };
  for (std::size_t index = 0; index < points.size(); ++index) {
    const std::uint32_t slot = sole[index];
    if (slot == 0) continue;
    const double offset = (points[index].z() - base[slot]) / binWidth(slot);
    // A patch's own points lie within its blocks' heights: more bins than this are no patch.
    if (!(offset >= 0.0 && offset < kMaxHeightBins)) continue;
    const auto n = static_cast<std::size_t>(offset);
    if (n >= bins[slot].size()) bins[slot].resize(n + 1);
    if (std::isnan(first_point[slot].x())) first_point[slot] = points[index];
    const auto u = static_cast<float>(across[slot].dot(points[index] - first_point[slot]));
    bins[slot][n].low = std::min(bins[slot][n].low, u);
    bins[slot][n].high = std::max(bins[slot][n].high, u);
  }
  std::vector<HeightRange> heights(slots);
  for (std::size_t slot = 1; slot < slots; ++slot) {
    std::size_t first = bins[slot].size(), last = 0;
    for (std::size_t n = 0; n < bins[slot].size(); ++n) {
      if (!(bins[slot][n].high - bins[slot][n].low >= min_width)) continue;
      first = std::min(first, n);
      last = n;
    }
    if (first > last) continue;  // nowhere wide: unknown, it decides no edge
    const double bin = binWidth(slot);
    const double slack = bin + 2.0 * fitted[slot].tolerance;
    heights[slot].low = static_cast<float>(base[slot] + static_cast<double>(first) * bin - slack);
    heights[slot].high = static_cast<float>(base[slot] + static_cast<double>(last + 1) * bin + slack);
  }
  return heights;
}

OutlineReach::OutlineReach(const std::vector<const std::vector<Eigen::Vector3d>*>& outline_of_slot,
                           const std::vector<PointPlane>& fitted, double near) {
  const std::size_t slots = outline_of_slot.size();
  std::vector<Eigen::AlignedBox3d> boxes(slots);
  for (std::size_t slot = 1; slot < slots; ++slot)
    if (outline_of_slot[slot] != nullptr)
      for (const Eigen::Vector3d& vertex : *outline_of_slot[slot])
        if (vertex.allFinite()) boxes[slot].extend(vertex);
  for (std::size_t a = 1; a < slots; ++a) {
    if (boxes[a].isEmpty()) continue;
    const Eigen::AlignedBox3d grown(boxes[a].min().array() - near, boxes[a].max().array() + near);
    for (std::size_t b = 1; b < slots; ++b) {
      if (a == b || boxes[b].isEmpty() || !grown.intersects(boxes[b])) continue;
      float least = std::numeric_limits<float>::infinity(), greatest = -least;
      for (const Eigen::Vector3d& vertex : *outline_of_slot[a]) {
        if (!vertex.allFinite()) continue;
        const auto distance = static_cast<float>(fitted[b].normal.dot(vertex) + fitted[b].offset);
        least = std::min(least, distance);
        greatest = std::max(greatest, distance);
      }
      reach_.emplace(pairKey(a, b), std::pair{least, greatest});
    }
  }
}

std::optional<std::pair<double, double>> OutlineReach::of(std::uint32_t a, std::uint32_t b) const {
  const auto found = reach_.find(pairKey(a, b));
  if (found == reach_.end()) return std::nullopt;
  return std::pair<double, double>{found->second.first, found->second.second};
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> OutlineReach::pairs() const {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> keys;
  keys.reserve(reach_.size());
  for (const auto& [key, extent] : reach_)
    keys.emplace_back(static_cast<std::uint32_t>(key >> 32), static_cast<std::uint32_t>(key & 0xffffffffU));
  return keys;
}

std::uint32_t behindEdge(std::uint32_t chosen, const Point& point, const Point* scanner,
                         std::span<const Candidate> candidates, const std::vector<PointPlane>& fitted,
                         const std::vector<double>& along_tolerance, const std::vector<std::int8_t>& seen_from,
                         const OutlineReach& reach, double slack, double tail) {
  if (chosen == 0 || (scanner != nullptr && !scanner->allFinite())) return chosen;
  const PointPlane& patch = fitted[chosen];
  std::uint32_t behind = chosen;
  double nearest = std::numeric_limits<double>::infinity();
  for (const Candidate& c : candidates) {
    const PointPlane& surface = fitted[c.slot];
    if (c.slot == chosen || std::abs(surface.normal.dot(patch.normal)) >= kEdgeCosine) continue;
    // A larger surface than the patch: a small face's plane is no boundary to trust to
    // a cm (the simulated lab turned 45°: a cabinet's 0.4 m end, 354 points, fitted 2.7
    // cm into its front, would have taken 600 of the front's points).
    if (surface.points <= patch.points) continue;
    // The scanner sees the surface's front: else nothing tells its noise from what lies
    // past it. Without the scanner, the side the surface is seen from stands for it.
    const double scanner_side =
        scanner != nullptr ? surface.normal.dot(*scanner) + surface.offset : static_cast<double>(seen_from[c.slot]);
    if (scanner_side * seen_from[c.slot] <= 0.0) continue;
    const double distance = surface.normal.dot(point) + surface.offset;
    // Past the plane from the scanner, within the surface's noise tail: along the beam
    // (range noise lies along it) where the surface's range noise is known.
    const bool along_known = std::isfinite(along_tolerance[c.slot]);
    const double units = along_known ? c.rank / along_tolerance[c.slot] : std::abs(distance) / surface.tolerance;
    if (scanner_side * distance >= 0.0 || units > tail) continue;
    const auto extent = reach.of(chosen, c.slot);
    if (!extent) continue;
    // The patch stays on the scanner's side of the plane: it ends there.
    const double past = scanner_side > 0.0 ? -extent->first : extent->second;
    if (past > slack + surface.tolerance) continue;
    if (units < nearest) {
      nearest = units;
      behind = c.slot;
    }
  }
  return behind;
}

std::vector<std::int8_t> seenFrom(std::span<const Point> points, std::span<const std::uint32_t> slot_of_point,
                                  const std::vector<PointPlane>& fitted,
                                  const std::function<Point(std::size_t)>& scanner_of) {
  std::vector<std::int64_t> votes(fitted.size(), 0);
  for (std::size_t index = 0; index < points.size(); ++index) {
    const std::uint32_t slot = slot_of_point[index];
    if (slot == 0) continue;
    const double side = fitted[slot].normal.dot(scanner_of(index)) + fitted[slot].offset;
    votes[slot] += side > 0.0 ? 1 : side < 0.0 ? -1 : 0;
  }
  std::vector<std::int8_t> seen_from(fitted.size(), 0);
  for (std::size_t slot = 1; slot < fitted.size(); ++slot)
    seen_from[slot] = votes[slot] > 0 ? 1 : votes[slot] < 0 ? -1 : 0;
  return seen_from;
}

std::uint32_t nearerAlongBeam(const Candidate& alone, std::span<const Candidate> tail,
                              const std::vector<PointPlane>& fitted, const std::vector<double>& along_tolerance,
                              double limit) {
  const PointPlane& patch = fitted[alone.slot];
  double best = alone.rank / along_tolerance[alone.slot];
  if (std::isnan(best)) return alone.slot;  // range noise unknown
  const bool beyond = best > 1.0;
  std::uint32_t chosen = alone.slot;
  std::size_t chosen_points = patch.points;
  for (const Candidate& c : tail) {
    const PointPlane& surface = fitted[c.slot];
    if (std::abs(surface.normal.dot(patch.normal)) >= kEdgeCosine || surface.points <= patch.points ||
        !std::isfinite(along_tolerance[c.slot]))
      continue;
    const double units = c.rank / along_tolerance[c.slot];
    if (beyond) {
      if (units < best && units <= limit) {
        best = units;
        chosen = c.slot;
      }
    } else if (units <= 1.0 && surface.points > chosen_points) {
      // Both planes within their range noise along the beam: either surface could have
      // returned the point, and as at an edge (likeliest) the larger takes it.
      chosen = c.slot;
      chosen_points = surface.points;
    }
  }
  return chosen;
}

std::uint32_t surfaceTail(std::uint32_t chosen, const Point& point, std::span<const Candidate> near,
                          const std::vector<PointPlane>& fitted, double limit, double ratio) {
  if (chosen == 0) return chosen;
  const PointPlane& patch = fitted[chosen];
  std::uint32_t surface = chosen;
  double nearest = std::numeric_limits<double>::infinity();
  for (const Candidate& c : near) {
    const PointPlane& other = fitted[c.slot];
    if (c.slot == chosen || static_cast<double>(other.points) < ratio * static_cast<double>(patch.points) ||
        std::abs(other.normal.dot(patch.normal)) >= kEdgeCosine)
      continue;
    const double units = planeDistance(other, point) / other.tolerance;
    if (units <= limit && units < nearest) {
      nearest = units;
      surface = c.slot;
    }
  }
  return surface;
}

std::int8_t levelSeenFrom(const Plane& plane, const PointPlane& fitted) {
  if (std::abs(fitted.normal.z()) < kLevelCosine) return 0;
  const std::int8_t up = fitted.normal.z() > 0.0 ? 1 : -1;
  switch (plane.label) {
    case PlaneClass::Floor:
    case PlaneClass::Table:
    case PlaneClass::Step: return up;
    case PlaneClass::Ceiling: return static_cast<std::int8_t>(-up);
    default: return 0;
  }
}

}  // namespace mlmap
