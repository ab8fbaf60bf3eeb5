#include "mlmap/planes/direction_vectors.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>

#include "smallest_axis.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap {
namespace {

// The moment sums run over a cell's neighbours once per block of the cell, and which
// neighbours count depends on the block (its height): a branch per neighbour mispredicts
// on every table edge. Instead each neighbour's terms sit in four-float lanes (GCC/Clang
// vector extensions, SSE2 or NEON without -march), masked to zero when it does not count,
// and added lane by lane. Each sum still adds the same terms in the same order as a
// scalar loop (a masked term adds +0.0F), so the sums are bit-identical to it.
using Lanes = float __attribute__((vector_size(16)));
using LaneMask = std::int32_t __attribute__((vector_size(16)));

Lanes keepIf(bool keep, Lanes terms) {
  const LaneMask mask = LaneMask{} - static_cast<std::int32_t>(keep);
  return reinterpret_cast<Lanes>(reinterpret_cast<LaneMask>(terms) & mask);
}

// A neighbour as the blocks of one cell see it: offsets from the cell's centre, with the
// terms of its moments that do not depend on the block.
struct alignas(16) Neighbour {
  Lanes plane;   // 1, dx, dy, dx²
  Lanes cross;   // dx·dy, dy², 0, 0
  Lanes offset;  // 1, dx, dy, z (its point's height); horizontal neighbours only
  float top;
  float bottom;
};

Neighbour neighbourAt(const PlaneBlock& block, const Eigen::Vector3f& centre) {
  const float dx = block.point.x() - centre.x();
  const float dy = block.point.y() - centre.y();
  return {Lanes{1.0F, dx, dy, dx * dx}, Lanes{dx * dy, dy * dy, 0.0F, 0.0F}, Lanes{1.0F, dx, dy, block.point.z()},
          block.top, block.bottom};
}

// Blocks of one cell share their neighbourhood: it is gathered once per cell, each
// class in its own list, and the sums are kept in float relative to the block (offsets
// of a few cells, heights of a few centimetres), then solved in double.
Eigen::Vector3f horizontalDirection(const PlaneBlock& self, const std::vector<Neighbour>& horizontal,
                                    float height_tolerance, double min_spread) {
  Lanes plane{}, cross{}, height{};  // n, Σx, Σy, Σx² | Σxy, Σy² | Σz, Σxz, Σyz, Σz²
  const float self_z = self.point.z();
  for (const Neighbour& other : horizontal) {
    const bool keep = std::abs(other.top - self.top) < height_tolerance;
    const float z = other.offset[3] - self_z;
    Lanes terms = other.offset;
    terms[3] = z;
    plane += keepIf(keep, other.plane);
    cross += keepIf(keep, other.cross);
    height += keepIf(keep, terms * z);  // z, dx·z, dy·z, z²
  }
  const float n = plane[0];
  if (n < 3.0F) return Eigen::Vector3f::Zero();
  const Eigen::Vector3d mean = Eigen::Vector3d(plane[1], plane[2], height[0]) / n;
  Eigen::Matrix3d covariance;
  covariance << plane[3], cross[0], height[1], cross[0], cross[1], height[2], height[1], height[2], height[3];
  covariance = covariance / n - mean * mean.transpose();
  const SmallestAxis smallest = smallestAxis(covariance);
  // The neighbourhood must spread in two directions, or its normal is arbitrary.
  if (smallest.middle_eigenvalue < min_spread) return Eigen::Vector3f::Zero();
  return orientConsistently(smallest.axis.cast<float>());
}

Eigen::Vector3f verticalDirection(const PlaneBlock& self, const std::vector<Neighbour>& vertical, double min_spread) {
  Lanes plane{}, cross{};  // n, Σx, Σy, Σx² | Σxy, Σy²
  for (const Neighbour& other : vertical) {
    const bool keep = !(other.bottom > self.top || other.top < self.bottom);
    plane += keepIf(keep, other.plane);
    cross += keepIf(keep, other.cross);
  }
  const float n = plane[0];
  if (n < 2.0F) return Eigen::Vector3f::Zero();
  const Eigen::Vector2d mean = Eigen::Vector2d(plane[1], plane[2]) / n;
  Eigen::Matrix2d covariance;
  covariance << plane[3], cross[0], cross[0], cross[1];
  covariance = covariance / n - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver;
  solver.computeDirect(covariance);
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
  // Not zeroed first: the loop writes every block's (each lies in one cell), and Eigen's
  // vectors are left uninitialised by their constructor, so the pages are first touched
  // by the threads that fill them.
  std::vector<Eigen::Vector3f> directions(grid.size());
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
        (block.vertical ? vertical : horizontal).push_back(neighbourAt(block, centre));
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
