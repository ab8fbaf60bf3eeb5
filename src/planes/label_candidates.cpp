// The patches a point may lie on (label_candidates.hpp).
#include "label_candidates.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

namespace mlmap {
namespace {

// |n_z| of the patches LevelCover holds: 20° of level, wider than kLevelCosine's 15° so
// that a refit leaning a patch a little does not take it out.
constexpr double kCoverCosine = 0.94;

// Whether the column of cell `at` holds a vertical block whose foot or top lies within
// `reach` of height z: where a level surface's strip can hide in that block.
bool byVerticalEnd(const MLMap& map, std::optional<CellIndex> at, double z, double reach) {
  if (!at) return false;
  for (const Block& block : map.blocks(*at))
    if (block.isVertical() && (std::abs(z - block.bottom()) <= reach || std::abs(z - block.height) <= reach))
      return true;
  return false;
}

}  // namespace

LabelCandidates::LabelCandidates(const MLMap& map, std::span<const Point> points,
                                 const std::vector<std::uint32_t>& slot_of_point, std::span<const std::int32_t> ids,
                                 const std::vector<PointPlane>& fitted, const std::vector<double>& along_tolerance,
                                 double level_gap)
    : map_(map),
      points_(points),
      slot_of_point_(slot_of_point),
      ids_(ids),
      fitted_(fitted),
      along_tolerance_(along_tolerance),
      reach_(map.cellSize()),
      // Cells round a face's foot that level patches' blocks are looked for where none lies
      // two cells round (level_gap).
      far_level_(std::max<std::int32_t>(kNearLevel,
                                        static_cast<std::int32_t>(std::ceil(level_gap / map.cellSize() - 1e-9)))) {}

// Where each level patch's blocks lie within far_level_ cells: every patch within 20° of
// level (the test for level stays the query's).
void LabelCandidates::coverLevelPatches() {
  if (far_level_ <= kNearLevel) return;
  std::vector<bool> nearly_level(fitted_.size(), false);
  for (std::size_t slot = 1; slot < fitted_.size(); ++slot)
    nearly_level[slot] = std::abs(fitted_[slot].normal.z()) >= kCoverCosine;
  level_cover_.emplace(map_, [this](std::int32_t id) { return slotOf(id); }, nearly_level, far_level_);
}

// Whether the cell holds, near height z, a level block that the detector gave to a patch
// that is not level: a face took the floor's strip in its column, where the floor's own
// blocks can lie two cells off (the simulated lab turned 2-10°: a floor point at a
// cabinet's foot had the face as its only candidate, and the face then touched the floor
// in issue 19's held-out measure). There, as by a vertical block's end, the level
// patches' blocks are looked for two cells round.
bool LabelCandidates::byFaceFoot(const CellIndex& cell, double z) const {
  for (const Block& block : map_.blocks(cell)) {
    if (block.plane <= 0 || block.isVertical() || z > block.height + reach_ || z < block.bottom() - reach_) continue;
    const std::uint32_t slot = slotOf(block.plane);
    if (slot != 0 && std::abs(fitted_[slot].normal.z()) < kLevelCosine) return true;
  }
  return false;
}

// How many cells round a place at height z the level patches' blocks are looked for: two
// by a vertical block's end or a face's foot, else one. The candidates' search (gather)
// and the test that the beam meets a level patch where it is (onPatch) look as far.
std::int32_t LabelCandidates::levelReach(const CellIndex& cell, double z) const {
  return byVerticalEnd(map_, cell, z, reach_) || byFaceFoot(cell, z) ? kNearLevel : kNear;
}

std::size_t LabelCandidates::gather(std::size_t index, const Eigen::Vector3d& beam,
                                  std::array<Candidate, kMaxCandidates>& out,
                                  std::array<Candidate, kMaxCandidates>* tail, std::size_t* tail_found) const {
  const Point& p = points_[index];
  std::size_t found = 0;
  if (tail_found != nullptr) *tail_found = 0;
  if (!p.allFinite()) return found;
  const auto consider = [&](std::uint32_t slot) {
    const PointPlane& plane = fitted_[slot];
    const double signed_distance = plane.normal.dot(p) + plane.offset;
    const double along = plane.normal.dot(beam);
    // Where the beam meets the plane, from the measured point along it (m).
    const double meets = std::abs(along) >= kMinIncidenceCosine ? -signed_distance / along : 0.0;
    const double rank = beam.isZero() ? std::abs(signed_distance) / plane.tolerance
                                      : std::abs(signed_distance) / std::max(kMinIncidenceCosine, std::abs(along));
    if (std::abs(signed_distance) > plane.tolerance) {
      // Across the plane a tail point lies no farther than along its beam.
      const double tail_reach =
          std::isfinite(along_tolerance_[slot]) ? std::max(plane.tolerance, along_tolerance_[slot]) : plane.tolerance;
      if (tail == nullptr || *tail_found == kMaxCandidates ||
          std::abs(signed_distance) > kTailTolerances * tail_reach)
        return;
      for (std::size_t c = 0; c < *tail_found; ++c)
        if ((*tail)[c].slot == slot) return;
      (*tail)[(*tail_found)++] = Candidate{slot, rank, meets};
      return;
    }
    if (found == kMaxCandidates) return;
    for (std::size_t c = 0; c < found; ++c)
      if (out[c].slot == slot) return;
    out[found++] = Candidate{slot, rank, meets};
  };
  if (slot_of_point_[index] != 0) consider(slot_of_point_[index]);
  const auto cell = map_.findCellOf(p.x(), p.y());
  if (cell && p.allFinite()) {
    const std::int32_t near = levelReach(*cell, p.z());
    const auto visitRing = [&](std::int32_t from, std::int32_t to) {
      for (std::int32_t di = -to; di <= to; ++di) {
        for (std::int32_t dj = -to; dj <= to; ++dj) {
          const std::int32_t ring = std::max(std::abs(di), std::abs(dj));
          if (ring < from) continue;
          const bool outer = ring > kNear;
          for (const Block& block : map_.blocks(CellIndex{cell->i + di, cell->j + dj})) {
            if (block.plane <= 0 || p.z() > block.height + reach_ || p.z() < block.bottom() - reach_) continue;
            const std::uint32_t slot = slotOf(block.plane);
            if (slot != 0 && (!outer || std::abs(fitted_[slot].normal.z()) >= kLevelCosine)) consider(slot);
          }
        }
      }
    };
    visitRing(0, near);
    // A point with faces alone as candidates is at a face's foot as surely as one whose
    // cell holds the face's block (byFaceFoot): level patches two cells round too (the
    // floor's points on box sides and risers of make_scene.py's rooms at 0.05 m: their
    // walls/floor/ceiling/table F1 0.970 -> 0.978, seeds 2-3; real scans the same).
    std::int32_t reached = near;
    if (near == kNear && found > 0) {
      bool level = false;
      for (std::size_t c = 0; c < found; ++c) level |= std::abs(fitted_[out[c].slot].normal.z()) >= kLevelCosine;
      if (!level) visitRing(kNear + 1, kNearLevel);
      reached = level ? kNear : kNearLevel;
    }
    // Past them, as far as a level surface's scan lines lie apart (level_gap), at the foot of
    // a face where plumb faces alone are candidates: a floor point at a box side's foot 8.5 m
    // out in a hall (planes_sweep.py's hall-2) had the floor's nearest block three cells off,
    // the next point of its own scan line, and went to the face. Plumb faces only: fr079's
    // steps at 10 cm, patches leaning 30° over the flight, gave band points to a small level
    // patch 0.5 m off. At a foot only (in the point's column and those round it the face's
    // blocks rise above the point, none lies below it): at a face's top a desk's top 0.5 m
    // away took the top strip of a cabinet's face beside it (office-4 at 2 cm of noise), and
    // halfway up a chair's back the strip at the height of the desk behind it (office-23).
    const auto facesOnly = [&] {
      for (std::size_t c = 0; c < found; ++c)
        if (std::abs(fitted_[out[c].slot].normal.z()) > kPlumbSine) return false;
      return found > 0;
    };
    const auto atFaceFoot = [&] {
      bool above = false;
      for (std::int32_t di = -1; di <= 1; ++di)
        for (std::int32_t dj = -1; dj <= 1; ++dj)
          for (const Block& block : map_.blocks(CellIndex{cell->i + di, cell->j + dj})) {
            const bool up = block.bottom() > p.z() + reach_, down = block.height < p.z() - reach_;
            if (block.plane <= 0 || !(up || down)) continue;
            const std::uint32_t slot = slotOf(block.plane);
            for (std::size_t c = 0; c < found; ++c) {
              if (out[c].slot != slot) continue;
              if (down) return false;
              above = true;
            }
          }
      return above;
    };
    if (reached == kNearLevel && level_cover_ && facesOnly() && atFaceFoot()) {
      level_cover_->forEachNear(*cell, [&](std::uint32_t slot) {
        if (std::abs(fitted_[slot].normal.z()) >= kLevelCosine) consider(slot);
      });
    }
  }
  return found;
}

}  // namespace mlmap
