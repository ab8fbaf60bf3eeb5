#include "mlmap/registration/voxel_hash_map.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "mlmap/error.hpp"

namespace mlmap::registration {
namespace {

// OctoMap's key range at depth 16: keys floor(c / resolution) + 32768 in [0, 65535].
constexpr std::int32_t kKeyMin = -32768;
constexpr std::int32_t kKeyMax = 32767;

bool inKeyRange(const VoxelKey& key) {
  return key.x >= kKeyMin && key.x <= kKeyMax && key.y >= kKeyMin && key.y <= kKeyMax && key.z >= kKeyMin &&
         key.z <= kKeyMax;
}

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

VoxelKey operator+(const VoxelKey& a, const VoxelKey& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }

// Blocks of 2^kBlockShift voxels a side. A wide search's cost is the blocks its box overlaps
// plus the occupied voxels in the blocks its sphere reaches. At 4 voxels (0.4 m at the maps'
// 0.1 m) an occupied block holds few of its 64 voxels (the stress benchmark's scans, tune
// split: mean 6.5-16, 90th percentile 16-32), and a 1.5 m gate's box holds ~600 blocks where it
// holds ~27,000 voxels: the wide basin's ICP runs took 4.5x less time searching (42 runs from
// 10-30 deg off, 32.9 -> 7.3 s, the same results to the bit).
constexpr int kBlockShift = 2;
constexpr std::int32_t kBlock = 1 << kBlockShift;
// Searches reaching beyond this many voxels go by blocks: nearer ones (the fine stage's 0.1 m
// gate) find their answer in the first shell or two of voxels. 1, 2 or 3 here: the same time
// on those 42 runs, within the load's noise.
constexpr double kBlockSearchVoxels = 2.0;

VoxelKey blockOf(const VoxelKey& key) {  // arithmetic shift: floor division for negative keys too
  return {key.x >> kBlockShift, key.y >> kBlockShift, key.z >> kBlockShift};
}

// The gap along one axis between a point at `f` (in [0, 1)) inside its cell and the cell
// `delta` cells away, in cells.
double cellGap(std::int32_t delta, double f) {
  if (delta > 0) return static_cast<double>(delta) - f;
  if (delta < 0) return f - 1.0 - static_cast<double>(delta);
  return 0.0;
}

}  // namespace

VoxelHashMap::VoxelHashMap(double voxel_size, std::size_t max_points_per_voxel)
    : voxel_size_(voxel_size), inverse_size_(1.0 / voxel_size), max_points_per_voxel_(max_points_per_voxel) {
  if (!(voxel_size > 0.0)) throw Error("voxel hash map: voxel size must be positive");
  if (max_points_per_voxel == 0) throw Error("voxel hash map: max points per voxel must be positive");
}

Point VoxelHashMap::centreOf(const VoxelKey& key) const {
  return Point(static_cast<double>(key.x) + 0.5, static_cast<double>(key.y) + 0.5, static_cast<double>(key.z) + 0.5) *
         voxel_size_;
}

void VoxelHashMap::addPoints(const std::vector<Point>& points) {
  // Which points find room in their voxel (the first max_points_per_voxel), counted per
  // voxel; then every voxel's points are packed again, old ones first, in one pass.
  std::vector<std::uint32_t> counts(table_.size());
  for (std::size_t v = 0; v < table_.size(); ++v) counts[v] = static_cast<std::uint32_t>(pointsIn(v));
  std::vector<std::pair<std::uint32_t, std::size_t>> accepted;  // (voxel, index in `points`)
  accepted.reserve(points.size());
  for (std::size_t p = 0; p < points.size(); ++p) {
    const Point& point = points[p];
    if (!point.allFinite()) continue;
    const VoxelKey key = voxelKeyOf(point, inverse_size_);
    if (!inKeyRange(key)) continue;
    const auto [voxel, inserted] = table_.insert(key);
    if (inserted) {
      counts.push_back(0);
      normals_.push_back(Normal::Zero());
      moments_.emplace_back();
      dirty_.push_back(0);
      sparse_.push_back(0);
      voxel_block_.push_back(blocks_.insert(blockOf(key)).first);
    }
    if (counts[voxel] >= max_points_per_voxel_) continue;
    ++counts[voxel];
    accepted.emplace_back(voxel, p);
    const Eigen::Vector3d d = point - centreOf(key);
    moments_[voxel].sum += d;
    moments_[voxel].outer.noalias() += d * d.transpose();
    dirty_[voxel] = 1;
  }
  if (accepted.empty()) return;

  std::vector<std::uint32_t> begin(table_.size() + 1, 0);
  for (std::size_t v = 0; v < table_.size(); ++v) begin[v + 1] = begin[v] + counts[v];
  std::vector<Point> packed(begin.back());
  std::vector<std::uint32_t> cursor(begin.begin(), begin.end() - 1);
  for (std::size_t v = 0; v + 1 < begin_.size(); ++v) {
    std::copy(points_.begin() + begin_[v], points_.begin() + begin_[v + 1], packed.begin() + cursor[v]);
    cursor[v] += begin_[v + 1] - begin_[v];
  }
  for (const auto& [voxel, p] : accepted) packed[cursor[voxel]++] = points[p];
  begin_ = std::move(begin);
  points_ = std::move(packed);
  if (block_voxels_.size() != table_.size()) indexBlocks();
}

void VoxelHashMap::indexBlocks() {
  std::vector<std::uint32_t> begin(blocks_.size() + 1, 0);
  for (const std::uint32_t block : voxel_block_) ++begin[block + 1];
  for (std::size_t b = 0; b < blocks_.size(); ++b) begin[b + 1] += begin[b];
  std::vector<std::uint32_t> cursor(begin.begin(), begin.end() - 1);
  block_voxels_.resize(voxel_block_.size());
  for (std::size_t v = 0; v < voxel_block_.size(); ++v) block_voxels_[cursor[voxel_block_[v]]++] = static_cast<std::uint32_t>(v);
  block_begin_ = std::move(begin);
}

// Calls visit(index) for each stored voxel within `radius` of `query` (its box, not its
// points), in shells of growing Chebyshev distance around the query's voxel, and stops
// once a shell lies beyond the radius. `visit` returns the radius to go on with, so a
// nearest-neighbour search shrinks it to the best distance found so far.
template <typename Visit>
void VoxelHashMap::visitVoxels(const Point& query, double radius, Visit&& visit) const {
  const VoxelKey own = voxelKeyOf(query, inverse_size_);
  const VoxelKey low = voxelKeyOf(query - Point::Constant(radius), inverse_size_);
  const VoxelKey high = voxelKeyOf(query + Point::Constant(radius), inverse_size_);
  // The query's offset inside its own voxel, in voxels: the box distance of a voxel
  // `delta` voxels away along an axis is (delta − 1 + 1 − f) or (−delta − 1 + f), clamped at 0.
  const Eigen::Vector3d fraction = query * inverse_size_ - Eigen::Vector3d(own.x, own.y, own.z);
  const double radius_voxels_sq = radius * radius * inverse_size_ * inverse_size_;
  double limit_sq = radius_voxels_sq;  // in voxels², shrinks with the visitor's radius
  const auto visitKey = [&](std::int32_t dx, std::int32_t dy, std::int32_t dz) {
    const VoxelKey key{own.x + dx, own.y + dy, own.z + dz};
    if (key.x < low.x || key.x > high.x || key.y < low.y || key.y > high.y || key.z < low.z || key.z > high.z) return;
    const double gx = cellGap(dx, fraction.x()), gy = cellGap(dy, fraction.y()), gz = cellGap(dz, fraction.z());
    if (gx * gx + gy * gy + gz * gz > limit_sq) return;
    const std::uint32_t index = table_.find(key);
    if (index == VoxelTable::kMissing) return;
    const double next_radius = visit(index);
    limit_sq = next_radius * next_radius * inverse_size_ * inverse_size_;
  };
  const std::int32_t max_shell =
      std::max({own.x - low.x, high.x - own.x, own.y - low.y, high.y - own.y, own.z - low.z, high.z - own.z});
  for (std::int32_t k = 0; k <= max_shell; ++k) {
    // Every voxel of shell k is at least (k − 1) voxels away from the query.
    if (static_cast<double>(k - 1) * static_cast<double>(k - 1) > limit_sq && k > 1) break;
    for (std::int32_t dx = -k; dx <= k; ++dx) {
      for (std::int32_t dy = -k; dy <= k; ++dy) {
        const bool on_face = std::abs(dx) == k || std::abs(dy) == k;
        for (std::int32_t dz = -k; dz <= k; dz += (on_face || k == 0) ? 1 : 2 * k) visitKey(dx, dy, dz);
      }
    }
  }
}

// As visitVoxels, for wide radii: shells of blocks around the query's block, and in each
// occupied block within the radius its voxels within it, nearest block first. The voxels
// visited are the same (those whose box lies within the visitor's radius when reached), in
// another order.
template <typename Visit>
void VoxelHashMap::visitBlocks(const Point& query, double radius, Visit&& visit) const {
  const VoxelKey own = voxelKeyOf(query, inverse_size_);
  const VoxelKey own_block = blockOf(own);
  const VoxelKey low = blockOf(voxelKeyOf(query - Point::Constant(radius), inverse_size_));
  const VoxelKey high = blockOf(voxelKeyOf(query + Point::Constant(radius), inverse_size_));
  const Eigen::Vector3d fraction = query * inverse_size_ - Eigen::Vector3d(own.x, own.y, own.z);  // in the voxel
  // ... and in its block, in blocks.
  const Eigen::Vector3d block_fraction =
      (Eigen::Vector3d(own.x - kBlock * own_block.x, own.y - kBlock * own_block.y, own.z - kBlock * own_block.z) +
       fraction) / static_cast<double>(kBlock);
  double limit_sq = radius * radius * inverse_size_ * inverse_size_;  // in voxels²
  // The query's own voxel first: a near answer there shrinks the radius before the blocks'
  // voxels, visited in storage order, are.
  const std::uint32_t own_voxel = table_.find(own);
  if (own_voxel != VoxelTable::kMissing) {
    const double next_radius = visit(own_voxel);
    limit_sq = next_radius * next_radius * inverse_size_ * inverse_size_;
  }
  const auto visitBlock = [&](std::int32_t bx, std::int32_t by, std::int32_t bz) {
    const VoxelKey key{own_block.x + bx, own_block.y + by, own_block.z + bz};
    if (key.x < low.x || key.x > high.x || key.y < low.y || key.y > high.y || key.z < low.z || key.z > high.z) return;
    const double gx = kBlock * cellGap(bx, block_fraction.x()), gy = kBlock * cellGap(by, block_fraction.y()),
                 gz = kBlock * cellGap(bz, block_fraction.z());
    if (gx * gx + gy * gy + gz * gz > limit_sq) return;
    const std::uint32_t block = blocks_.find(key);
    if (block == VoxelTable::kMissing) return;
    for (std::uint32_t k = block_begin_[block]; k < block_begin_[block + 1]; ++k) {
      const std::uint32_t voxel = block_voxels_[k];
      if (voxel == own_voxel) continue;
      const VoxelKey& at = table_.key(voxel);
      const double vx = cellGap(at.x - own.x, fraction.x()), vy = cellGap(at.y - own.y, fraction.y()),
                   vz = cellGap(at.z - own.z, fraction.z());
      if (vx * vx + vy * vy + vz * vz > limit_sq) continue;
      const double next_radius = visit(voxel);
      limit_sq = next_radius * next_radius * inverse_size_ * inverse_size_;
    }
  };
  const std::int32_t max_shell = std::max({own_block.x - low.x, high.x - own_block.x, own_block.y - low.y,
                                           high.y - own_block.y, own_block.z - low.z, high.z - own_block.z});
  for (std::int32_t k = 0; k <= max_shell; ++k) {
    // Every block of shell k is at least (k − 1) blocks away from the query.
    const double nearest_voxels = static_cast<double>(kBlock * (k - 1));
    if (k > 1 && nearest_voxels * nearest_voxels > limit_sq) break;
    for (std::int32_t dx = -k; dx <= k; ++dx) {
      for (std::int32_t dy = -k; dy <= k; ++dy) {
        const bool on_face = std::abs(dx) == k || std::abs(dy) == k;
        for (std::int32_t dz = -k; dz <= k; dz += (on_face || k == 0) ? 1 : 2 * k) visitBlock(dx, dy, dz);
      }
    }
  }
}

std::optional<Neighbour> VoxelHashMap::nearest(const Point& query, double max_distance) const {
  if (!(max_distance >= 0.0) || points_.empty()) return std::nullopt;
  double best_sq = max_distance * max_distance;
  std::uint32_t best_point = VoxelTable::kMissing;
  std::uint32_t best_voxel = VoxelTable::kMissing;
  const auto visit = [&](std::uint32_t voxel) {
    for (std::uint32_t k = begin_[voxel]; k < begin_[voxel + 1]; ++k) {
      const double distance_sq = (points_[k] - query).squaredNorm();
      if (distance_sq <= best_sq) {
        best_sq = distance_sq;
        best_point = k;
        best_voxel = voxel;
      }
    }
    return std::sqrt(best_sq);
  };
  if (max_distance * inverse_size_ > kBlockSearchVoxels) {
    visitBlocks(query, max_distance, visit);
  } else {
    visitVoxels(query, max_distance, visit);
  }
  if (best_point == VoxelTable::kMissing) return std::nullopt;
  return Neighbour{points_[best_point], normals_[best_voxel], std::sqrt(best_sq)};
}

std::vector<Point> VoxelHashMap::within(const Point& query, double radius) const {
  std::vector<Point> found;
  if (!(radius >= 0.0)) return found;
  const double radius_sq = radius * radius;
  visitVoxels(query, radius, [&](std::uint32_t voxel) {
    for (std::uint32_t k = begin_[voxel]; k < begin_[voxel + 1]; ++k) {
      if ((points_[k] - query).squaredNorm() <= radius_sq) found.push_back(points_[k]);
    }
    return radius;
  });
  return found;
}

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
            const VoxelKey& at = table_.key(block_voxels_[k]);
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
  std::vector<double> distances;
  const std::size_t stride = std::max<std::size_t>(1, table_.size() / std::max<std::size_t>(1, max_voxels));
  for (std::size_t v = 0; v < table_.size(); v += stride) {
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
      distances.push_back(dof * std::abs(normals_[v].dot(points_[k] - mean)));
    }
  }
  if (distances.empty()) return 0.0;
  auto middle = distances.begin() + static_cast<long>(distances.size() / 2);
  std::nth_element(distances.begin(), middle, distances.end());
  return 1.4826 * *middle;  // MAD -> standard deviation of a Gaussian
}

std::vector<Point> VoxelHashMap::points() const { return points_; }

}  // namespace mlmap::registration
