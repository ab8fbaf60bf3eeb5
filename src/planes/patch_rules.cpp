#include "patch_rules.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>

#include "id_set.hpp"
#include "pca_sums.hpp"

namespace mlmap {

std::vector<std::uint32_t> withEdges(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                                     const PlaneScorer& scorer, std::vector<std::uint32_t> matching,
                                     const CandidatePlane& plane, double epsilon, double kappa_rad, int threads) {
  IdSet in_plane(grid.size());
  for (const std::uint32_t id : matching) in_plane.insert(id);
  const auto cos_edge = static_cast<float>(std::cos(std::min(2.0 * kappa_rad, std::numbers::pi / 2)));
  const auto reach = static_cast<float>(epsilon);
  // Blocks joining in a ring around the frontier: the ring of a floor's 150 000 blocks
  // at 2 cm is worth two threads; each keeps what it finds, and the set of blocks
  // that join does not depend on the order they are found in.
  auto ring = [&](std::span<const std::uint32_t> frontier, std::vector<std::uint32_t>& found) {
    for (const std::uint32_t id : frontier) {
      grid.forEachNeighbour(grid.blocks()[id].cell, 1, [&](std::uint32_t other) {
        if (in_plane.contains(other) || scorer.taken(other)) return;
        const Eigen::Vector3f& direction = directions[other];
        if (direction.squaredNorm() > 0.0F && std::abs(direction.dot(plane.normal)) < cos_edge) return;
        if (std::abs(plane.normal.dot(grid.blocks()[other].point - plane.point)) >= reach) return;
        found.push_back(other);
      });
    }
  };
  constexpr std::size_t kParallelFrontier = 16384;
  std::vector<std::uint32_t> frontier = std::move(matching);
  std::vector<std::vector<std::uint32_t>> found(1);
  while (!frontier.empty()) {
    const std::span<const std::uint32_t> all(frontier);
    if (frontier.size() < kParallelFrontier || threads == 1) {
      found.resize(1);
      found[0].clear();
      ring(all, found[0]);
    } else {
      found.assign(2, {});
      const std::size_t half = frontier.size() / 2;
#pragma omp parallel for schedule(static) num_threads(2)
      for (int part = 0; part < 2; ++part) {
        ring(part == 0 ? all.first(half) : all.subspan(half), found[static_cast<std::size_t>(part)]);
      }
    }
    frontier.clear();
    for (const std::vector<std::uint32_t>& part : found) {
      for (const std::uint32_t id : part) {
        if (in_plane.contains(id)) continue;
        in_plane.insert(id);
        frontier.push_back(id);
      }
    }
  }
  return in_plane.ascending();
}

double directionSpread(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                       const std::vector<std::uint32_t>& ids, const CandidatePlane& plane) {
  double weighted = 0.0;
  double weight = 0.0;
  for (const std::uint32_t id : ids) {
    const double cosine = std::min(1.0F, std::abs(directions[id].dot(plane.normal)));
    weighted += grid.blocks()[id].surface * std::acos(cosine);
    weight += grid.blocks()[id].surface;
  }
  return weight > 0.0 ? weighted / weight * 180.0 / std::numbers::pi : 0.0;
}

bool isThin(const BlockGrid& grid, const Patch& patch, const CandidatePlane& plane, double min_width) {
  PcaSums pca;
  for (const std::uint32_t id : patch.blocks) {
    const PlaneBlock& block = grid.blocks()[id];
    pca.addBlock((block.point - plane.point).cast<double>(), block.vertical ? 0.5 * (block.top - block.bottom) : 0.0,
                 1.0);
  }
  // The spread across the plane: the covariance in the plane's own basis.
  Eigen::Vector3d u_axis;
  Eigen::Vector3d v_axis;
  planeBasis(plane.normal.cast<double>(), u_axis, v_axis);
  Eigen::Matrix<double, 3, 2> basis;
  basis << u_axis, v_axis;
  const Eigen::Matrix2d in_plane = basis.transpose() * pca.covariance() * basis;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(in_plane);
  const double minor = std::sqrt(std::max(0.0, solver.eigenvalues()(0)));
  return minor < min_width;
}

}  // namespace mlmap
