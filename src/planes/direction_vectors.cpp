#include "mlmap/planes/direction_vectors.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap {
namespace {

// A neighbour as the blocks of one cell see it: offsets from the cell's centre.
struct Neighbour {
  float dx;
  float dy;
  float z;       // its point's height
  float top;
  float bottom;
};

// Blocks of one cell share their neighbourhood: it is gathered once per cell, each
// class in its own list, and the sums are kept in float relative to the block (offsets
// of a few cells, heights of a few centimetres), then solved in double.
Eigen::Vector3f horizontalDirection(const PlaneBlock& self, const std::vector<Neighbour>& horizontal,
                                    float height_tolerance, double min_spread) {
  float n = 0.0F, sx = 0.0F, sy = 0.0F, sz = 0.0F;
  float xx = 0.0F, xy = 0.0F, xz = 0.0F, yy = 0.0F, yz = 0.0F, zz = 0.0F;
  for (const Neighbour& other : horizontal) {
    if (std::abs(other.top - self.top) >= height_tolerance) continue;
    const float z = other.z - self.point.z();
    n += 1.0F;
    sx += other.dx;
    sy += other.dy;
    sz += z;
    xx += other.dx * other.dx;
    xy += other.dx * other.dy;
    xz += other.dx * z;
    yy += other.dy * other.dy;
    yz += other.dy * z;
    zz += z * z;
  }
  if (n < 3.0F) return Eigen::Vector3f::Zero();
  const Eigen::Vector3d mean = Eigen::Vector3d(sx, sy, sz) / n;
  Eigen::Matrix3d covariance;
  covariance << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  covariance = covariance / n - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  // The neighbourhood must spread in two directions, or its normal is arbitrary.
  if (solver.eigenvalues()(1) < min_spread) return Eigen::Vector3f::Zero();
  return orientConsistently(solver.eigenvectors().col(0).cast<float>());
}

Eigen::Vector3f verticalDirection(const PlaneBlock& self, const std::vector<Neighbour>& vertical, double min_spread) {
  float n = 0.0F, sx = 0.0F, sy = 0.0F, xx = 0.0F, xy = 0.0F, yy = 0.0F;
  for (const Neighbour& other : vertical) {
    if (other.bottom > self.top || other.top < self.bottom) continue;
    n += 1.0F;
    sx += other.dx;
    sy += other.dy;
    xx += other.dx * other.dx;
    xy += other.dx * other.dy;
    yy += other.dy * other.dy;
  }
  if (n < 2.0F) return Eigen::Vector3f::Zero();
  const Eigen::Vector2d mean = Eigen::Vector2d(sx, sy) / n;
  Eigen::Matrix2d covariance;
  covariance << xx, xy, xy, yy;
  covariance = covariance / n - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(covariance);
  if (solver.eigenvalues()(1) < min_spread) return Eigen::Vector3f::Zero();
  const Eigen::Vector2d normal = solver.eigenvectors().col(0);
  return orientConsistently(Eigen::Vector3f(static_cast<float>(normal.x()), static_cast<float>(normal.y()), 0.0F));
}

}  // namespace

Eigen::Vector3f orientConsistently(const Eigen::Vector3f& normal) {
  const float length = normal.norm();
  if (!(length > 0.0F)) return Eigen::Vector3f::Zero();
  Eigen::Vector3f unit = normal / length;
  // Pick the sign by the largest component, with z first so near-horizontal surfaces
  // (|n_z| large) always point up.
  if (std::abs(unit.z()) >= std::max(std::abs(unit.x()), std::abs(unit.y()))) {
    if (unit.z() < 0.0F) unit = -unit;
  } else if (std::abs(unit.x()) >= std::abs(unit.y())) {
    if (unit.x() < 0.0F) unit = -unit;
  } else if (unit.y() < 0.0F) {
    unit = -unit;
  }
  return unit;
}

std::vector<Eigen::Vector3f> directionVectors(const BlockGrid& grid, const DirectionConfig& config) {
  std::vector<Eigen::Vector3f> directions(grid.size(), Eigen::Vector3f::Zero());
  const auto cells = static_cast<std::int64_t>(grid.cellCount());
  const double min_spread = 0.1 * grid.cellSize() * grid.cellSize();
  const auto& blocks = grid.blocks();
#ifdef _OPENMP
  const int threads = config.threads > 0 ? config.threads : omp_get_max_threads();
#endif
#pragma omp parallel num_threads(threads)
  {
    std::vector<Neighbour> horizontal;
    std::vector<Neighbour> vertical;
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t cell = 0; cell < cells; ++cell) {
      const std::uint32_t begin = grid.firstBlockOfCell(static_cast<std::size_t>(cell));
      const std::uint32_t end = grid.firstBlockOfCell(static_cast<std::size_t>(cell) + 1);
      if (begin == end) continue;
      const Eigen::Vector3f& centre = blocks[begin].point;
      horizontal.clear();
      vertical.clear();
      grid.forEachNeighbour(blocks[begin].cell, config.radius, [&](std::uint32_t other) {
        const PlaneBlock& block = blocks[other];
        (block.vertical ? vertical : horizontal)
            .push_back({block.point.x() - centre.x(), block.point.y() - centre.y(), block.point.z(), block.top, block.bottom});
      });
      for (std::uint32_t id = begin; id < end; ++id) {
        directions[id] = blocks[id].vertical ? verticalDirection(blocks[id], vertical, min_spread)
                                             : horizontalDirection(blocks[id], horizontal, config.height_tolerance, min_spread);
      }
    }
  }
  return directions;
}

}  // namespace mlmap
