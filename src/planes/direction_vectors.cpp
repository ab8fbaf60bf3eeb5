#include "mlmap/planes/direction_vectors.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap {
namespace {

Eigen::Vector3f horizontalDirection(const BlockGrid& grid, std::uint32_t id, const DirectionConfig& config) {
  const auto& blocks = grid.blocks();
  const PlaneBlock& self = blocks[id];
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  int count = 0;
  // Coordinates relative to the block keep the sums well conditioned far from the origin.
  grid.forEachNeighbour(self.cell, config.radius, [&](std::uint32_t other) {
    const PlaneBlock& block = blocks[other];
    if (block.vertical || std::abs(block.top - self.top) >= config.height_tolerance) return;
    const Eigen::Vector3d p = (block.point - self.point).cast<double>();
    sum += p;
    outer += p * p.transpose();
    ++count;
  });
  if (count < 3) return Eigen::Vector3f::Zero();
  const Eigen::Vector3d mean = sum / count;
  const Eigen::Matrix3d covariance = outer / count - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  // The neighbourhood must spread in two directions, or its normal is arbitrary.
  const double spread = 0.1 * grid.cellSize() * grid.cellSize();
  if (solver.eigenvalues()(1) < spread) return Eigen::Vector3f::Zero();
  return orientConsistently(solver.eigenvectors().col(0).cast<float>());
}

Eigen::Vector3f verticalDirection(const BlockGrid& grid, std::uint32_t id, const DirectionConfig& config) {
  const auto& blocks = grid.blocks();
  const PlaneBlock& self = blocks[id];
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  Eigen::Matrix2d outer = Eigen::Matrix2d::Zero();
  int count = 0;
  grid.forEachNeighbour(self.cell, config.radius, [&](std::uint32_t other) {
    const PlaneBlock& block = blocks[other];
    if (!block.vertical || block.bottom > self.top || block.top < self.bottom) return;
    const Eigen::Vector2d p = (block.point.head<2>() - self.point.head<2>()).cast<double>();
    sum += p;
    outer += p * p.transpose();
    ++count;
  });
  if (count < 2) return Eigen::Vector3f::Zero();
  const Eigen::Vector2d mean = sum / count;
  const Eigen::Matrix2d covariance = outer / count - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(covariance);
  const double spread = 0.1 * grid.cellSize() * grid.cellSize();
  if (solver.eigenvalues()(1) < spread) return Eigen::Vector3f::Zero();
  const Eigen::Vector2d normal = solver.eigenvectors().col(0);
  return orientConsistently(Eigen::Vector3f(static_cast<float>(normal.x()),
                                            static_cast<float>(normal.y()), 0.0F));
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
  std::vector<Eigen::Vector3f> directions(grid.size());
  const auto count = static_cast<std::int64_t>(grid.size());
#ifdef _OPENMP
  const int threads = config.threads > 0 ? config.threads : omp_get_max_threads();
#endif
#pragma omp parallel for schedule(dynamic, 1024) num_threads(threads)
  for (std::int64_t k = 0; k < count; ++k) {
    const auto id = static_cast<std::uint32_t>(k);
    directions[id] = grid.blocks()[id].vertical ? verticalDirection(grid, id, config)
                                                : horizontalDirection(grid, id, config);
  }
  return directions;
}

}  // namespace mlmap
