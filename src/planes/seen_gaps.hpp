// Beyond the paper: level surfaces apart. The patch split (patches.hpp) connects a
// plane's blocks across a one-cell gap, so that a surface whose scan lines miss a cell
// here and there stays one patch. Two tables a hand apart at one height are then one
// patch too, though the scanner saw the floor between them; a table top cut by a
// monitor's shadow, where nothing was seen, is rightly one.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/patches.hpp"
#include "outline_runs.hpp"

namespace mlmap {

// m: the level plane's (`normal`, through `point`) height over a cell's centre.
double heightAt(const BlockGrid& grid, const Eigen::Vector3d& normal, const Eigen::Vector3d& point, CellIndex cell);

// Calls visit(cell) for the cells strictly between `from` and `to` on the line joining
// them, one per Chebyshev step, until it returns true; returns whether it did.
template <typename Visit>
bool anyCellBetween(CellIndex from, CellIndex to, Visit&& visit) {
  const int steps = std::max(std::abs(from.i - to.i), std::abs(from.j - to.j));
  for (int step = 1; step < steps; ++step) {
    const double t = static_cast<double>(step) / steps;
    const CellIndex cell{static_cast<std::int32_t>(std::lround(from.i + t * (to.i - from.i))),
                         static_cast<std::int32_t>(std::lround(from.j + t * (to.j - from.j)))};
    if (visit(cell)) return true;
  }
  return false;
}

// Which side of a level plane lies past it, away from the scanner: below a surface seen
// from above (a floor, a table), above one seen from below (a ceiling).
enum class FarSide { Below, Above };

// Whether the scanner saw past the level plane (`normal`, through `point`) on the cells
// strictly between `from` and `to`: one of them holds a block more than `tolerance`
// beyond the plane on its far side and none at the plane.
bool seenPast(const BlockGrid& grid, const Eigen::Vector3d& normal, const Eigen::Vector3d& point, CellIndex from,
              CellIndex to, double tolerance, FarSide far_side = FarSide::Below);

// Whether most of the blocks' cells hold map surface above the plane: a table under a
// ceiling. What lies past a level surface is on the far side from the scanner, which
// the map does not keep; a ceiling, with nothing above it, is seen from below, and what
// hangs under it in a gap (a lamp, a cabinet's top) is no view past it.
bool seenFromAbove(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
                   const Eigen::Vector3d& point, double tolerance);

// Cuts each patch of a level plane seen from above into its pieces that touch cell to cell, joined again
// across the gaps nobody saw past (seenPast). `outline_runs` (per patch) are emptied for
// the patches cut: their outlines are rasterised again. Patches stay sorted largest
// first. Planes more than 45° from level, and those not seen from above, are left alone.
void splitAtSeenGaps(const BlockGrid& grid, std::vector<Patch>& patches, std::vector<std::vector<Segment>>& outline_runs,
                     const Eigen::Vector3d& normal, const Eigen::Vector3d& point, double tolerance);

}  // namespace mlmap
