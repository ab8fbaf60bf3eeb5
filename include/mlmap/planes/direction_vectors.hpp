// Direction vectors (section V, Fig. 4): for every block, the normal of the surface
// formed by the block and the blocks of the SAME class within Chebyshev radius r.
// Horizontal blocks: 3D PCA over (x, y, h) of nearby horizontal blocks at a similar
// height (so a table top does not mix with the floor). Vertical blocks: 2D PCA over
// the positions of nearby vertical blocks whose extents overlap, giving (nx, ny, 0).
// A block's position across is its points' mean where the map keeps it (not the
// paper's cell centre): a wall turned to the grid is then a line of blocks, not a
// staircase whose steps a window of r cells mistakes for the grid's axis.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "mlmap/planes/block_grid.hpp"

namespace mlmap {

// Where the blocks scatter across their surface by a good part of the window, r cells
// leave a direction too uncertain for the seeds' agreement test: on 3DTK's corridor
// ceiling at 5 cm cells (blocks 5.5 cm RMS about its plane, 1-2 points each) the
// directions of r = 2 lie a median 11 deg off its normal, and the ceiling was no patch.
// Such a level block's window widens, a cell at a time up to max_radius, until the
// normal's standard error, from the window's own residual and spread, is at most
// max_tilt (walls' windows and windows too small to measure their scatter do not).
struct DirectionConfig {
  int radius = 2;                 // cells, Chebyshev radius r of the neighbourhood
  float height_tolerance = 0.08F; // m, horizontal neighbours must lie this close in height
  int max_radius = 0;             // cells, the widest window; <= radius: never wider
  double max_tilt = 0.0;          // rad, per axis; 0: never wider
  // A wall block whose window holds a corner takes the line through itself that most of
  // the window's blocks lie on (direction_vectors.cpp, cornerDirection); false: the
  // principal axis of them all, as the paper's Fig. 4.
  bool corners = true;
  int threads = 0;                // OpenMP threads; 0 = OpenMP's default
};

struct DirectionField {
  // Unit vectors, indexed by block id, oriented consistently (horizontal: n_z ≥ 0;
  // vertical: the larger of |n_x|, |n_y| positive). Zero where the neighbourhood is too
  // small or too thin to define a surface.
  std::vector<Eigen::Vector3f> vectors;
  // rad, per block: the standard error of its direction per axis, from its window's
  // residual and spread (infinite where the window holds too few blocks to tell).
  std::vector<float> tilts;
};

DirectionField directionField(const BlockGrid& grid, const DirectionConfig& config);

// directionField(grid, config) from `earlier`, the field (same config) of another grid
// of the same map whose blocks differ from `grid`'s only at the ids `changed` (the same
// blocks of the same cells, some of them other in depth class or height: another level
// band). Only the blocks whose windows, up to max_radius, hold a changed block are
// computed again; where those are most of the map, all are.
DirectionField updatedDirectionField(const BlockGrid& grid, const DirectionConfig& config, DirectionField earlier,
                                     const std::vector<std::uint32_t>& changed);

// The vectors alone.
std::vector<Eigen::Vector3f> directionVectors(const BlockGrid& grid, const DirectionConfig& config);

// The same orientation rule, for any normal.
Eigen::Vector3f orientConsistently(const Eigen::Vector3f& normal);

}  // namespace mlmap
