// Beyond the paper: surfaces far from the scanner. There its scan lines lie further
// apart than a direction window (PCL's room scans: the floor 5-7 m out is lines of
// points 10 cm apart, the lines 0.35-0.7 m apart), so a block's window holds one line
// or none: the block gets no direction, no candidate is seeded on it, no plane matches
// it, and the piece a plane does match is a strip one line wide that the patch rules
// drop. A person sees the floor go on to the far wall. After the search, such blocks
// join a patch whose plane they lie on (within its ε), linked to it block by block
// across gaps of at most `max_gap` in which nothing was seen past the plane.
#pragma once

#include <cstdint>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "patch_set.hpp"
#include "plane_scorer.hpp"

namespace mlmap {

// Whether the unit `normal` lies within max_tilt_rad of level or of plumb (the classes'
// floors, ceilings, tables and walls): the only planes sparse blocks join.
bool levelOrPlumb(const Eigen::Vector3d& normal, double max_tilt_rad);

// Whether block `id` is a rung of a wall seen from afar: a short block with another of
// its cell less than `ladder_gap` above or below. No level plane takes one (fr079 at
// 5 cm: a table's plane took 96 points of the wall beside it).
bool isWallRung(const BlockGrid& grid, std::uint32_t id, double ladder_gap);

struct SparseGrowth {
  double max_gap = 0.0;       // m, the longest step from block to block (in the plane)
  double kappa_rad = 0.0;     // blocks with a direction join within 2 κ of the plane's normal
  double max_tilt_rad = 0.0;  // only planes this close to level or to plumb grow
  double ladder_gap = 0.0;    // m: ErmsmConfig::ladder_gap, what tells a sparse wall's rungs
};

// The blocks of `candidates` (free blocks near the plane: those within `epsilon`, and
// for a plane within 45° of level only level ones that are no rung of a wall) that `patch`
// reaches: each within max_gap of the patch or of a block that joined, with no block seen
// past the plane in the cells between (for a level plane, on the side away from where it
// was seen; for a wall, on both sides within 0.3 m: an opening). `patch` ascending.
// Returns the joined ids ascending; none for a plane more than max_tilt_rad from both
// level and plumb.
std::vector<std::uint32_t> sparseGrowth(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                                        const std::vector<std::uint32_t>& candidates,
                                        const std::vector<std::uint32_t>& patch, const CandidatePlane& plane,
                                        double epsilon, const SparseGrowth& config);

// Grows each patch of `set` from index `first` on in turn (patch k split on references[k];
// blocks another patch grew into are no longer free): labels its new blocks, adds their
// surface to surfaces[k] and leaves its outline to be rasterised again.
void growPatches(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions, const PlaneScorer& scorer,
                 const std::vector<CandidatePlane>& references, std::vector<double>& surfaces, PatchSet& set,
                 const SparseGrowth& config, std::size_t first = 0);

}  // namespace mlmap
