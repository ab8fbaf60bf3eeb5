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
#include <vector>

#include "mlmap/planes/block_grid.hpp"

namespace mlmap {

struct DirectionConfig {
  int radius = 2;                 // cells, Chebyshev radius r of the neighbourhood
  float height_tolerance = 0.08F; // m, horizontal neighbours must lie this close in height
  int threads = 0;                // OpenMP threads; 0 = OpenMP's default
};

// Unit vectors, indexed by block id, oriented consistently (horizontal: n_z ≥ 0;
// vertical: the larger of |n_x|, |n_y| positive). Zero where the neighbourhood is too
// small or too thin to define a surface.
std::vector<Eigen::Vector3f> directionVectors(const BlockGrid& grid, const DirectionConfig& config);

// The same orientation rule, for any normal.
Eigen::Vector3f orientConsistently(const Eigen::Vector3f& normal);

}  // namespace mlmap
