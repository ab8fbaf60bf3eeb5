// Beyond the paper: a wall seen in pieces. The patch split (patches.hpp) cuts a plane
// wherever its blocks leave a gap; a gap in a wall is either an opening, through which
// the scanner saw what lies behind (a side corridor's floor, the next room), or a part
// of the wall nobody saw (the scanner's blind sector, a cabinet in front). Pieces of
// one wall with nothing seen behind the gap between them are one patch.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/patches.hpp"

namespace mlmap {

// Joins, along the wall (the plane's horizontal axis), neighbouring pieces of `patches`
// unless blocks lie on both sides of the plane over the gap between them, further than
// `epsilon` from it and closer than `reach` (a doorway shows the floor beyond it), and
// unless nothing at all lies beside the gap's inside and it is more than twice as long as
// the pieces either side of it (walls of two rooms in line, the solid between them unseen).
// Only pieces of at least `min_blocks` blocks and `min_surface` surface units, patches
// on their own, take part: fragments stay as they are. Planes that are not walls
// (|n_z| ≥ 0.2) are left alone: between tables at one height the floor shows below and
// the ceiling may be far above. Patches stay sorted largest first; a joined patch's
// blocks stay ascending (its outline, traced later, is its largest piece's). Pieces whose
// mean distances from the plane differ by more than `max_step` are layers (sheets.hpp),
// not one wall: they stay apart.
void joinUnseenGaps(const BlockGrid& grid, std::vector<Patch>& patches, const Eigen::Vector3d& normal,
                    const Eigen::Vector3d& point, double epsilon, std::size_t min_blocks, double min_surface,
                    double reach = 0.3, double max_step = std::numeric_limits<double>::infinity());

}  // namespace mlmap
