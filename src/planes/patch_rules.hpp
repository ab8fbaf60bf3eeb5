// Internal to eRMSM, beyond the paper: the rules applied to an accepted plane before
// its blocks leave the pool — its edge blocks, and the tests that tell a real plane's
// patch from a curved surface's facet or a one-cell fringe.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/patches.hpp"
#include "plane_scorer.hpp"

namespace mlmap {

// The cosine of the widest angle an edge block's direction may make with a plane's
// normal: 2 κ, at most 90°.
inline float edgeCosine(double kappa_rad) {
  return static_cast<float>(std::cos(std::min(2.0 * kappa_rad, std::numbers::pi / 2)));
}

// Blocks on the plane's edges, where a corner or a rim bends their direction vectors
// past κ (or leaves them none), join the plane when they touch its matching blocks, lie
// within ε and point within 2κ of it. Otherwise room corners are left over and later
// form small diagonal "walls". Returns the ids ascending.
std::vector<std::uint32_t> withEdges(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                                     const PlaneScorer& scorer, std::vector<std::uint32_t> matching,
                                     const CandidatePlane& plane, double epsilon, double kappa_rad);

// A curved surface (a pillar) fits planes only facet by facet, with directions fanning
// out across each facet: a real plane's blocks agree with its normal. The mean angle,
// in degrees, of the blocks' directions to the normal, weighted by surface.
double directionSpread(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                       const std::vector<std::uint32_t>& ids, const CandidatePlane& plane);
// Whether directionSpread(...) > max_deg, decided from cheap bounds of each angle where
// they settle it (nearly always: the ceiling's 150 000 angles cost an arc cosine each),
// else from directionSpread itself: the same answer either way.
// `threads`: OpenMP threads for large planes; the answer does not depend on them.
bool spreadExceeds(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                   const std::vector<std::uint32_t>& ids, const CandidatePlane& plane, double max_deg,
                   int threads = 1);

// Noise alone spreads directions: a block's direction off by a standard error s per
// axis lies a mean s √(π/2) from the normal (a Rayleigh length). That for the median s
// of the blocks `ids`, in degrees (each at most κ; blocks whose window was too small to
// tell left out): the median, so that a small patch's edge blocks, whose windows reach
// over its border, do not excuse its spread.
double noiseSpread(const std::vector<float>& tilts, const std::vector<std::uint32_t>& ids, double kappa_rad);
// The spread a plane may show: a curved surface's own spread of max_deg on top of the
// noise's, the two adding as independent errors do (in squares).
inline double spreadLimit(double max_deg, double noise_deg) { return std::hypot(max_deg, noise_deg); }

// The median distance of the blocks `ids` (PlaneBlock::point: across at their points'
// mean, up at h) from the plane, m: how thick they lie round it, robust to the few a
// neighbouring object pulls away.
double medianDistance(const BlockGrid& grid, const std::vector<std::uint32_t>& ids, const CandidatePlane& plane);

// The points a patch's plane is fitted to (PcaSums::addBlock): one per level block, two
// per vertical block (its top and its bottom). A patch needs ErmsmConfig::min_patch_blocks
// of them: a wall's face three cells wide is as well determined as a floor's six cells,
// and counting blocks lost the 0.5 m ends of lockers and cabinets (1.2-1.8 m tall, three
// vertical blocks at 10 cm cells) of the simulated corridor (issue 19).
std::size_t fitPoints(const BlockGrid& grid, const Patch& patch);

// A patch one cell wide is no surface: it is the fringe of a wall standing on a cell
// boundary (stray points in the next column) or a line of clutter. True when its blocks
// spread across the plane less than `min_width` (m, standard deviation) in some direction;
// for a plumb patch, along the wall by `min_width` and up it by a riser's (8 cm) points.
bool isThin(const BlockGrid& grid, const Patch& patch, const CandidatePlane& plane, double min_width,
            int threads = 1);

}  // namespace mlmap
