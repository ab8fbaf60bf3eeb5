// Internal to eRMSM, beyond the paper: no flat patch on a curved surface. A pillar, a bin
// or a round wall is no plane, but a strip of it a few cells wide lies within ε of one (a
// pillar of 0.2 m radius at 5 cm cells: a strip 0.2-0.25 m wide, the arc 2.4-3.7 cm off its
// chord), and the spread rule on the blocks' directions does not always refuse it: where a
// window spans most of the pillar, neighbouring blocks see much the same arc. The simulated
// lab turned 30° kept a facet on its bin and two on its pillar; the corridor, aligned and
// turned 15°, one or two on its bins (bench/planes_sweep.py: all of the held-out variants'
// false patches there). The points tell: across such a patch their distance from its plane
// follows a parabola, and across a flat one only the noise.
#pragma once

#include "patch_set.hpp"

namespace mlmap {

// Drops each patch that is not level (tilted more than 45° from it) whose points bend
// across it: the distance of its blocks' points from its plane, fitted as a parabola in
// the patch's horizontal direction, (1) explains at least 40 % of their squared distance
// from the plane (their scatter within each block counted, so noise weighs against it);
// (2) is significant over its blocks (F >= 10 for the parabola's term); and (3) turns the
// surface's normal across the patch by more than κ / 3 (what tells two faces of a crease
// apart, creases.hpp): a wall bowed by a centimetre over metres turns by well under a
// degree and stays. A patch that bends so is judged again without its blocks whose points
// lie beyond `band` (m, its ε) from its plane, where those are few (curved.cpp): a few blocks
// of another face at a flat wall's end bend the parabola too. Its blocks go back to no
// patch; ids are renumbered in order and the block labels follow. Needs the blocks' point
// moments (a map without them: nothing dropped). Returns the number dropped.
std::size_t dropCurved(const BlockGrid& grid, PatchSet& set, double kappa_rad, double band);

}  // namespace mlmap
