// Internal to eRMSM, beyond the paper: two surfaces a step apart in one patch. A
// candidate's slab is ε = 3 σ thick either side, σ the range noise; two touching desks
// whose tops differ by 1-3 cm lie within it, and the search takes both tops as one patch
// (bench/office_rooms.py's offices 22 and 23: tops 2.8 and 1.4 cm apart, one "table"
// through both, its plane tilted between them). The range noise is not what a surface's
// points spread by across it: seen at a glancing angle, a desk top's points lie within a
// few mm of it (1 cm of range noise at 13° below the horizon: 2.3 mm up), so the step is
// many times their spread. Each block keeps its points' moments: where neighbouring blocks
// of a patch differ along its normal by more than the patch's own roughness allows (its
// points' spread, or how far its neighbouring blocks differ elsewhere), the patch holds a
// seam, and the blocks either side of it are two surfaces.
#pragma once

#include <cstdint>
#include <vector>

#include "patch_set.hpp"

namespace mlmap {

struct SeamConfig {
  double kappa_rad = 0.0;  // describePatch's: the pieces' fits stay within it of the patch's
  double noise = 0.0;      // m, σ, describePatch's
  int min_blocks = 6;      // a piece needs as many blocks (ErmsmConfig::min_patch_blocks)
  double min_area = 0.0;   // m², and as much surface (ErmsmConfig::min_patch_area)
  int threads = 1;         // patches searched at once (0: OpenMP's default)
};

// After classification: each level patch but the floor's and the ceiling's (their pieces
// are one level each whatever their heights: mergeLevels) whose blocks keep their points is
// cut at its seams. Its blocks are grouped where neighbours (cells one apart) differ along
// its normal by at most kSeamStep times the patch's roughness (the larger of its blocks'
// points' spread, the median over its blocks of their RMS along the normal, and the 95th
// percentile of its neighbouring blocks' differences); blocks whose points spread by more
// than kOneSurfaceSpread times the spread (a cell across the seam, holding both surfaces)
// join none. Where two groups as large as a patch must be meet side by side (not over the
// same cells: layers) and their blocks within two cells of each other lie more than the
// step apart in the median, each is a patch; the other blocks go to the piece whose plane
// lies nearest their points among those that hold a block within two cells (else among
// all). The first piece keeps the patch's id and the others are appended with its class
// and its flag in `landings` (classifyPlanes'; may be null), their outlines pending.
// Returns the number of patches cut.
std::size_t splitAtSeams(const BlockGrid& grid, PatchSet& set, const SeamConfig& config,
                         std::vector<std::uint8_t>* landings = nullptr);

// How far apart, in the patch's spreads, two surfaces must lie to be told apart:
// normal densities of equal spread s are bimodal from 2 s apart, and at 3 s their points
// overlap by 13 % (each surface's beyond the midpoint: 7 %).
inline constexpr double kSeamStep = 3.0;

}  // namespace mlmap
