// VoxelHashMap's normals and surface noise: the planes of the voxels' neighbourhoods.
#include "mlmap/registration/voxel_hash_map.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "voxel_blocks.hpp"

namespace mlmap::registration {
namespace {

using voxel_blocks::blockOf;
using voxel_blocks::operator+;

// The PCA normal of a neighbourhood from its moments (about any nearby point), or zero when it
// is not planar; `sparse` says whether it was too sparse to tell (too few points, or one line).
Normal planeNormal(std::size_t count, const Eigen::Vector3d& sum, const Eigen::Matrix3d& outer,
                   const NormalConfig& config, bool& sparse) {
  sparse = count < config.min_neighbours;
  if (sparse) return Normal::Zero();
  const double n = static_cast<double>(count);
  const Eigen::Vector3d mean = sum / n;
  const Eigen::Matrix3d covariance = (outer - n * mean * mean.transpose()) / n;
  // The closed-form 3×3 solver: a few times faster than the iterative one, and exact enough
  // for the well-separated smallest eigenvalue of a planar patch (the only case kept below).
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  const Eigen::Vector3d eigenvalues = solver.eigenvalues();  // ascending
  const double total = eigenvalues.sum();
  // Planar: thin across (low curvature) and spread in two directions (not a line or a
  // strip of one scan line, whose normal can turn about the line).
  const bool thin = total > 0.0 && eigenvalues[0] / total <= config.max_curvature;
  sparse = thin && !(eigenvalues[1] > 0.05 * eigenvalues[2]);
  if (thin && !sparse) return solver.eigenvectors().col(0).normalized();
  return Normal::Zero();
}

// Voxel offsets whose centres lie within `radius` voxels of the origin's centre.
std::vector<VoxelKey> sphereStencil(double radius) {
  const auto reach = static_cast<std::int32_t>(std::floor(radius));
  std::vector<VoxelKey> offsets;
  for (std::int32_t dx = -reach; dx <= reach; ++dx) {
    for (std::int32_t dy = -reach; dy <= reach; ++dy) {
      for (std::int32_t dz = -reach; dz <= reach; ++dz) {
        if (static_cast<double>(dx * dx + dy * dy + dz * dz) <= radius * radius) offsets.push_back({dx, dy, dz});
      }
    }
  }
  return offsets;
}

}  // namespace

void VoxelHashMap::estimateNormals(const NormalConfig& config) {
  stencil_ = sphereStencil(config.radius * inverse_size_);
  const std::vector<VoxelKey>& stencil = stencil_;
  // The wider neighbourhoods a sparse voxel tries in turn (the radius doubling), in voxels.
  std::vector<double> wider;
  for (double radius = 2.0 * config.radius; radius <= config.max_radius * (1.0 + 1e-9); radius *= 2.0) {
    wider.push_back(radius * inverse_size_);
  }
  // The voxels to (re)estimate: those that gained points and, when only some did, the
  // neighbours whose stencil reaches them (their neighbourhood changed too), and every voxel
  // whose last normal needed a wider neighbourhood (few: the sparse far field; re-estimating
  // them all is cheaper than marking through the widest stencil).
  const std::size_t voxels = table_.size();
  std::vector<std::uint32_t> todo;
  if (static_cast<std::size_t>(std::count(dirty_.begin(), dirty_.end(), 1)) == voxels) {
    todo.resize(voxels);
    for (std::size_t v = 0; v < voxels; ++v) todo[v] = static_cast<std::uint32_t>(v);
  } else {
    std::vector<char> marked(voxels, 0);
    for (std::size_t v = 0; v < voxels; ++v) {
      if (!wider.empty() && sparse_[v] != 0) marked[v] = 1;
      if (dirty_[v] == 0) continue;
      for (const VoxelKey& offset : stencil) {  // the stencil is symmetric
        const std::uint32_t index = table_.find(table_.key(static_cast<std::uint32_t>(v)) + offset);
        if (index != VoxelTable::kMissing) marked[index] = 1;
      }
    }
    for (std::size_t v = 0; v < voxels; ++v) {
      if (marked[v] != 0) todo.push_back(static_cast<std::uint32_t>(v));
    }
  }
  // A neighbour of a voxel: its offset (in voxels) and index.
  struct Found {
    VoxelKey offset;
    std::uint32_t index;
  };
  // The stored voxels of one stencil about `voxel`, in the stencil's order.
  const auto byStencil = [&](std::uint32_t voxel, const std::vector<VoxelKey>& offsets, std::vector<Found>& found) {
    found.clear();
    for (const VoxelKey& offset : offsets) {
      const std::uint32_t index = table_.find(table_.key(voxel) + offset);
      if (index != VoxelTable::kMissing) found.push_back({offset, index});
    }
  };
  // The same for a wide sphere (sphereStencil(radius)) without a lookup per offset: the
  // occupied blocks it overlaps, their voxels within it, sorted into the stencil's order (by
  // x, y, z offset) so the sums below add up in the same order, to the same bits. A sparse
  // voxel's 0.8 m stencil is ~2,100 offsets, its box ~350 blocks, mostly empty.
  const auto byBlocks = [&](std::uint32_t voxel, double radius, std::vector<Found>& found) {
    found.clear();
    const VoxelKey& key = table_.key(voxel);
    const auto reach = static_cast<std::int32_t>(std::floor(radius));
    const VoxelKey low = blockOf({key.x - reach, key.y - reach, key.z - reach});
    const VoxelKey high = blockOf({key.x + reach, key.y + reach, key.z + reach});
    for (std::int32_t bx = low.x; bx <= high.x; ++bx) {
      for (std::int32_t by = low.y; by <= high.y; ++by) {
        for (std::int32_t bz = low.z; bz <= high.z; ++bz) {
          const std::uint32_t block = blocks_.find({bx, by, bz});
          if (block == VoxelTable::kMissing) continue;
          for (std::uint32_t k = block_begin_[block]; k < block_begin_[block + 1]; ++k) {
            const VoxelKey& at = block_voxel_keys_[k];
            const VoxelKey offset{at.x - key.x, at.y - key.y, at.z - key.z};
            const auto length_sq = static_cast<double>(offset.x * offset.x + offset.y * offset.y + offset.z * offset.z);
            if (length_sq <= radius * radius) found.push_back({offset, block_voxels_[k]});
          }
        }
      }
    }
    std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) {
      return std::tie(a.offset.x, a.offset.y, a.offset.z) < std::tie(b.offset.x, b.offset.y, b.offset.z);
    });
  };
  // The PCA normal over a voxel's neighbours; `sparse` as planeNormal's.
  const auto normalOver = [&](const std::vector<Found>& found, bool& sparse) {
    std::size_t points = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();  // about this voxel's centre
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    for (const auto& [offset, index] : found) {
      const Moments& moments = moments_[index];
      // Moments about the neighbour's centre, moved to this voxel's: d' = d + shift.
      const Eigen::Vector3d shift = Eigen::Vector3d(offset.x, offset.y, offset.z) * voxel_size_;
      const double n_points = static_cast<double>(pointsIn(index));
      points += pointsIn(index);
      sum += moments.sum + n_points * shift;
      outer += moments.outer + moments.sum * shift.transpose() + shift * moments.sum.transpose() +
               n_points * shift * shift.transpose();
    }
    return planeNormal(points, sum, outer, config, sparse);
  };
  // Each voxel writes only its own normal, so the result does not depend on the thread count.
  const long count = static_cast<long>(todo.size());
#pragma omp parallel
  {
    std::vector<Found> found;
#pragma omp for schedule(dynamic, 256)
    for (long n = 0; n < count; ++n) {
      const std::uint32_t voxel = todo[static_cast<std::size_t>(n)];
      bool sparse = false;
      byStencil(voxel, stencil, found);
      Normal normal = normalOver(found, sparse);
      sparse_[voxel] = sparse ? 1 : 0;
      for (std::size_t level = 0; sparse && level < wider.size(); ++level) {
        byBlocks(voxel, wider[level], found);
        normal = normalOver(found, sparse);
      }
      normals_[voxel] = normal;
    }
  }
  std::fill(dirty_.begin(), dirty_.end(), 0);
}

double VoxelHashMap::surfaceNoise(std::size_t max_voxels) const {
  const std::size_t stride = std::max<std::size_t>(1, table_.size() / std::max<std::size_t>(1, max_voxels));
  const auto sampled = static_cast<std::int64_t>((table_.size() + stride - 1) / stride);
  // Each thread collects its voxels' distances; the median does not depend on their order.
  std::vector<double> distances;
#pragma omp parallel if (sampled >= 1000)
  {
    std::vector<double> mine;
#pragma omp for schedule(static) nowait
    for (std::int64_t s = 0; s < sampled; ++s) {
      const auto v = static_cast<std::size_t>(s) * stride;
      if (normals_[v].isZero()) continue;
      const VoxelKey own = table_.key(static_cast<std::uint32_t>(v));
      std::size_t count = 0;
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();  // about this voxel's centre
      for (const VoxelKey& offset : stencil_) {
        const std::uint32_t index = table_.find(own + offset);
        if (index == VoxelTable::kMissing) continue;
        count += pointsIn(index);
        sum += moments_[index].sum + static_cast<double>(pointsIn(index)) *
                                         Eigen::Vector3d(offset.x, offset.y, offset.z) * voxel_size_;
      }
      if (count <= 3) continue;
      const Point mean = centreOf(own) + sum / static_cast<double>(count);
      // A plane fitted to n points leaves n − 3 degrees of freedom across it: scale so the
      // spread estimates one point's noise, not its deviation from a plane fitted through it.
      const double dof = std::sqrt(static_cast<double>(count) / static_cast<double>(count - 3));
      for (std::uint32_t k = begin_[v]; k < begin_[v + 1]; ++k) {
        mine.push_back(dof * std::abs(normals_[v].dot(points_[k] - mean)));
      }
    }
#pragma omp critical(surface_noise_distances)
    distances.insert(distances.end(), mine.begin(), mine.end());
  }
  if (distances.empty()) return 0.0;
  auto middle = distances.begin() + static_cast<long>(distances.size() / 2);
  std::nth_element(distances.begin(), middle, distances.end());
  return 1.4826 * *middle;  // MAD -> standard deviation of a Gaussian
}

}  // namespace mlmap::registration
