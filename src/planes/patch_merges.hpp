// Internal to eRMSM, beyond the paper: merging the patches of one surface that the search
// accepted apart (coplanar pieces, the pieces of a floor or a ceiling).
#pragma once

#include <cstdint>
#include <vector>

#include "patch_set.hpp"

namespace mlmap {

// Patches of one real plane found apart (a refit that tilted a little, a wall on a
// cell boundary) are merged when they are coplanar within ε (or the smaller may be the
// larger's noise tail: within 3.5 of the larger's RMS), parallel within κ / 2
// and touch on the grid; level ones meet at one height where they meet cell to cell, and
// (`noise` > 0) their points lie about one plane within a sheet's step. A merged group's
// outline is left pending; `noise` σ, m, as describePatch's. Patches of one family (the
// same non-negative value in `families`, one per plane; empty: none) never join, not
// through others either: the faces one patch was split into (creases.hpp).
void mergeCoplanar(const BlockGrid& grid, PatchSet& set, double epsilon, double kappa_rad, double noise,
                   const std::vector<int>& families = {});

// After classification: floor and ceiling patches are one level each, however far
// apart (a floor seen between furniture, a ceiling either side of a beam); a landing
// (flagged in `landings`, one per plane; classifyPlanes) is floor at its own height and
// joins none. The flags follow the planes into their merged order. A merged level's
// outline is left pending.
void mergeLevels(const BlockGrid& grid, PatchSet& set, double kappa_rad, double noise,
                 std::vector<std::uint8_t>* landings = nullptr);

}  // namespace mlmap
