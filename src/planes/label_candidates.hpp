// Internal to the point labels: the patches a point may lie on — those whose planes it
// lies within tolerance of, among its collecting block's patch and the patches of the
// blocks round it (refinePointLabels then chooses among them, edge_choice.hpp).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "edge_choice.hpp"
#include "level_cover.hpp"
#include "mlmap/map/ml_map.hpp"
#include "mlmap/planes/point_labels.hpp"

namespace mlmap {

// How many cells round a point its candidate patches' blocks are looked for: one, and two
// for level patches (kLevelCosine). Where a wall or a cabinet stands on the floor, the
// column holding its foot holds the floor's strip there too, in the vertical block
// (section IV joins them), and a face on a cell boundary fills both columns beside it: the floor's nearest own
// block can lie two cells from a floor point at the foot, and that point went to the face
// (the simulated lab at 5 cm: 9 floor points on 8 faces standing on it, each face then
// "touching" the floor in issue 19's held-out measure). So the second ring is looked at
// only for a point by the foot or the top of a vertical block in its own cell, and only for
// level patches: with every patch looked for two cells away, the neighbouring tilted
// blocks of plane_seg's steps at 10 cm took each other's edges. Where plumb faces alone
// are candidates even so, level patches are looked for as far as a level surface's scan
// lines lie apart (PointLabelRefinement::level_gap).
constexpr std::int32_t kNear = 1;
constexpr std::int32_t kNearLevel = 2;

// How far past a surface's tolerance (3σ) its noise tail is looked for (behindEdge): 6σ,
// beyond which a normal tail holds one point in 500 million.
constexpr double kTailTolerances = 2.0;

// The slot of patch `id` among `ids` (ascending; slot k + 1 holds ids[k]), 0 for none.
inline std::uint32_t slotOfId(std::span<const std::int32_t> ids, std::int32_t id) {
  const auto found = std::lower_bound(ids.begin(), ids.end(), id);
  return found != ids.end() && *found == id ? static_cast<std::uint32_t>(found - ids.begin()) + 1 : 0;
}

class LabelCandidates {
 public:
  // `ids`: the patches' ids ascending, slot k + 1 holding ids[k] (slot 0: none);
  // `fitted` and `along_tolerance` by slot, read at each query (the fits move them);
  // `slot_of_point`: each point's collecting block's slot.
  LabelCandidates(const MLMap& map, std::span<const Point> points, const std::vector<std::uint32_t>& slot_of_point,
                  std::span<const std::int32_t> ids, const std::vector<PointPlane>& fitted,
                  const std::vector<double>& along_tolerance, double level_gap);

  std::uint32_t slotOf(std::int32_t id) const { return slotOfId(ids_, id); }
  // How many cells round a place at height z the level patches' blocks are looked for.
  std::int32_t levelReach(const CellIndex& cell, double z) const;
  // Indexes where the level patches' blocks lie (LevelCover) for the search past two cells;
  // until then it stops at two. Called once the planes are nearly final.
  void coverLevelPatches();
  // The patches point `index` lies on (within tolerance of their refitted planes), among its
  // collecting block's and those of the blocks round it that reach its height, into `out`;
  // returns their count. `beam`: the point's unit beam, or zero where unknown. `tail`
  // (optional): the patches whose planes lie beyond their tolerance but within
  // kTailTolerances of it, and `tail_found` their count.
  std::size_t gather(std::size_t index, const Eigen::Vector3d& beam, std::array<Candidate, kMaxCandidates>& out,
                     std::array<Candidate, kMaxCandidates>* tail = nullptr, std::size_t* tail_found = nullptr) const;

 private:
  bool byFaceFoot(const CellIndex& cell, double z) const;

  const MLMap& map_;
  std::span<const Point> points_;
  const std::vector<std::uint32_t>& slot_of_point_;
  std::span<const std::int32_t> ids_;
  const std::vector<PointPlane>& fitted_;
  const std::vector<double>& along_tolerance_;
  double reach_;            // m, a block reaches a point's height within this (a cell)
  std::int32_t far_level_;  // cells, the search past two (level_gap)
  std::optional<LevelCover> level_cover_;
};

}  // namespace mlmap
