// Internal to eRMSM: a block's direction vector as the fits of direction_vectors.cpp
// return it, and a wall block's line through the positions of its window's wall blocks
// (Fig. 4), also where the window holds a corner.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <vector>

namespace mlmap {

// A block's direction and the standard error of its angle (radians, per axis; infinite
// where the window holds no more blocks than the fit has unknowns): the residual's
// variance s² = λ₀ n / (n − k) over the spread along the window's thinnest way in the
// surface, s / √(n λ₁).
struct Direction {
  Eigen::Vector3f vector = Eigen::Vector3f::Zero();
  double tilt = std::numeric_limits<double>::infinity();
};

// Its tilt from a fit of `unknowns` parameters to n blocks.
double tiltOf(double residual_variance, double spread_variance, double n, double unknowns);

// The variance across the principal axis of a 2 × 2 covariance.
double smallerEigenvalue(const Eigen::Matrix2d& covariance);

// A wall's line through its window: the principal axis of its blocks' positions (m),
// none where they spread less than `min_spread` (m²) along it.
Direction lineDirection(const Eigen::Matrix2d& covariance, double n, double min_spread);

// Where a window holds a corner (the end of a cabinet, a wall piece between two door
// jambs: every block within r cells of a turn), its blocks lie on two lines and their
// principal axis on neither. Then the line through the block itself that most of them
// lie on, within `reach` cells, fitted again to those: a 0.4 m face at 10 cm cells keeps
// its own direction. None where those scatter about it by more than `max_residual` (m):
// blocks round a pillar fill the band about a chord. `positions`: the window's wall
// blocks, `self` the block's own (cells, from the window's centre cell).
Direction cornerDirection(const std::vector<Eigen::Vector2f>& positions, const Eigen::Vector2f& self, float reach,
                          double max_residual, double cell, double min_spread);

}  // namespace mlmap
