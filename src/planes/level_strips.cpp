// Which of a level patch and a face keeps the strip where they meet (level_strips.hpp).
#include "level_strips.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace mlmap {
namespace {

// Whether `inner` lies within `outer` across the ground (x and y), `margin` round it.
bool withinAcross(const Eigen::AlignedBox3d& inner, const Eigen::AlignedBox3d& outer, double margin) {
  return inner.min().x() >= outer.min().x() - margin && inner.min().y() >= outer.min().y() - margin &&
         inner.max().x() <= outer.max().x() + margin && inner.max().y() <= outer.max().y() + margin;
}

}  // namespace

std::vector<HeightRange> outlineHeights(const std::vector<const Plane*>& plane_of_slot) {
  std::vector<HeightRange> heights(plane_of_slot.size());
  for (std::size_t slot = 0; slot < plane_of_slot.size(); ++slot) {
    const Plane* plane = plane_of_slot[slot];
    if (plane == nullptr) continue;
    HeightRange& range = heights[slot];
    if (!plane->bounds.isEmpty()) {
      range = {static_cast<float>(plane->bounds.min().z()), static_cast<float>(plane->bounds.max().z())};
      continue;
    }
    for (const Eigen::Vector3d& corner : plane->outline) {
      range.low = std::min(range.low, static_cast<float>(corner.z()));
      range.high = std::max(range.high, static_cast<float>(corner.z()));
    }
  }
  return heights;
}

std::vector<PatchExtent> patchExtents(std::span<const Point> points, std::span<const std::uint32_t> slot_of_point,
                                      const std::vector<PointPlane>& fitted, double stray_share) {
  const std::size_t slots = fitted.size();
  std::vector<PatchExtent> extent(slots);
  std::vector<std::array<std::vector<float>, 3>> along(slots);
  for (std::size_t index = 0; index < points.size(); ++index) {
    const std::uint32_t slot = slot_of_point[index];
    if (slot == 0 || !(planeDistance(fitted[slot], points[index]) <= fitted[slot].tolerance)) continue;
    extent[slot].reach.extend(points[index]);
    if (std::abs(fitted[slot].normal.z()) >= kLevelCosine) continue;  // most points, and no face
    for (int axis = 0; axis < 3; ++axis) along[slot][axis].push_back(static_cast<float>(points[index][axis]));
  }
  for (std::size_t slot = 1; slot < slots; ++slot) {
    if (along[slot][0].empty()) continue;
    Eigen::Vector3d low, high;
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<float>& values = along[slot][axis];
      const auto at = [&values](double share) {
        const auto k = static_cast<std::ptrdiff_t>(share * static_cast<double>(values.size() - 1));
        std::nth_element(values.begin(), values.begin() + k, values.end());
        return static_cast<double>(values[static_cast<std::size_t>(k)]);
      };
      low[axis] = at(stray_share);
      high[axis] = at(1.0 - stray_share);
    }
    extent[slot].box = Eigen::AlignedBox3d(low, high);
  }
  return extent;
}

LevelStrips::LevelStrips(const std::vector<PointPlane>& fitted, const std::vector<std::int8_t>& seen_from,
                         std::vector<PatchExtent> extents, std::vector<HeightRange> outline_heights, double reach,
                         double riser_max, double tail)
    : fitted_(fitted),
      seen_from_(seen_from),
      extents_(std::move(extents)),
      outline_heights_(std::move(outline_heights)),
      reach_(reach),
      riser_max_(riser_max),
      tail_(tail) {
  for (std::size_t slot = 1; slot < fitted_.size(); ++slot)
    if (std::abs(fitted_[slot].normal.z()) >= kLevelCosine && !extents_[slot].reach.isEmpty())
      level_slots_.push_back(static_cast<std::uint32_t>(slot));
}

Strip LevelStrips::of(std::uint32_t level_slot, std::uint32_t face, const Point& p) const {
  const PointPlane& level = fitted_[level_slot];
  if (std::abs(level.normal.z()) < kLevelCosine || std::abs(fitted_[face].normal.z()) >= kLevelCosine) return Strip::kNone;
  if (seen_from_[level_slot] == 0 || (seen_from_[level_slot] > 0) != (level.normal.z() > 0.0)) return Strip::kNone;
  const double height = -(level.normal.x() * p.x() + level.normal.y() * p.y() + level.offset) / level.normal.z();
  const HeightRange& range = outline_heights_[face];
  const double near = level.tolerance + reach_;
  if (range.high <= height + near && range.low < height - riser_max_) return Strip::kRim;
  const Eigen::AlignedBox3d& inner = extents_[face].box;
  const Eigen::AlignedBox3d& outer = extents_[level_slot].reach;
  if (inner.isEmpty() || outer.isEmpty()) return Strip::kNone;
  const bool within = withinAcross(inner, outer, near);
  const bool foot_there = std::abs(extents_[face].reach.min().z() - height) <= near ||
                          std::abs(inner.min().z() - height) <= near;
  return within && foot_there && inner.max().z() > height + riser_max_ ? Strip::kFoot : Strip::kNone;
}

bool LevelStrips::pastFace(std::uint32_t level, Strip strip, const Point& p) const {
  if (strip == Strip::kNone || seen_from_[level] == 0) return false;
  const double side = fitted_[level].normal.dot(p) + fitted_[level].offset;
  // The face stands on the side the surface is seen from and hangs under the other.
  const double face_side = strip == Strip::kFoot ? seen_from_[level] : -seen_from_[level];
  return side * face_side < 0.0;
}

std::uint32_t LevelStrips::stripOnUnseenLevel(std::uint32_t face, const Point& p, std::span<const Candidate> near) const {
  const PatchExtent& extent = extents_[face];
  if (std::abs(fitted_[face].normal.z()) >= kLevelCosine || extent.box.isEmpty()) return face;
  // Only near the face's foot (by either measure of of()) or its top, a few cells round.
  const double low = std::min(extent.reach.min().z(), extent.box.min().z());
  const bool at_foot = p.z() >= low - 3.0 * reach_ && p.z() <= extent.box.min().z() + 3.0 * reach_;
  const HeightRange& range = outline_heights_[face];
  const bool at_top = p.z() >= extent.box.max().z() - 3.0 * reach_ &&
                      p.z() <= std::max<double>(extent.box.max().z(), range.high) + 3.0 * reach_;
  if (!at_foot && !at_top) return face;
  for (const std::uint32_t level : level_slots_) {
    const Eigen::AlignedBox3d& ground = extents_[level].reach;
    const double distance = planeDistance(fitted_[level], p), tolerance = fitted_[level].tolerance;
    if (!withinAcross(Eigen::AlignedBox3d(p, p), ground, reach_) || distance > tail_ * tolerance) continue;
    const bool candidate = std::any_of(near.begin(), near.end(), [level](const Candidate& c) { return c.slot == level; });
    const Strip strip = candidate ? Strip::kNone : of(level, face, p);
    if (strip == Strip::kNone) continue;
    if (distance <= tolerance || pastFace(level, strip, p)) return level;
  }
  return face;
}

}  // namespace mlmap
