// Internal to eRMSM, beyond the paper: no patch along an edge. Where two surfaces meet
// (a wall and the ceiling, two walls), a cell's block holds points of both, and its
// direction lies between theirs; a run of such blocks along the edge can take a plane of
// its own, a strip tilted between the two (3DTK's corridor: strips 12-23° off level along
// the wall's top; issue 19: "slanted strips along edges, small diagonal pieces in corners").
#pragma once

#include "patch_set.hpp"

namespace mlmap {

// Drops each patch that lies along the edge of two larger patches it touches, which meet
// at 45° or more, its normal between theirs and at least κ/2 from each: a strip (most of
// its blocks touch both) or a piece across a corner (most of its blocks lie within ε of
// one of their planes). Its blocks go back to no patch (their points to the two
// surfaces' planes when labelled); ids are renumbered in order and the block labels follow.
void dropBevels(const BlockGrid& grid, PatchSet& set, double epsilon, double kappa_rad);

}  // namespace mlmap
