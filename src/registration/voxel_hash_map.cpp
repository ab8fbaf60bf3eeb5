#include "mlmap/registration/voxel_hash_map.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <tuple>

#include "mlmap/error.hpp"
#include "voxel_blocks.hpp"

namespace mlmap::registration {
namespace {

using voxel_blocks::blockOf;
using voxel_blocks::kBlock;
using voxel_blocks::kBlockShift;
using voxel_blocks::operator+;

// OctoMap's key range at depth 16: keys floor(c / resolution) + 32768 in [0, 65535].
constexpr std::int32_t kKeyMin = -32768;
constexpr std::int32_t kKeyMax = 32767;

bool inKeyRange(const VoxelKey& key) {
  return key.x >= kKeyMin && key.x <= kKeyMax && key.y >= kKeyMin && key.y <= kKeyMax && key.z >= kKeyMin &&
         key.z <= kKeyMax;
}

// Searches reaching beyond this many voxels go by blocks: nearer ones (the fine stage's 0.1 m
// gate) find their answer in the first shell or two of voxels. 1, 2 or 3 here: the same time
// on those 42 runs, within the load's noise.
constexpr double kBlockSearchVoxels = 2.0;

// The gap along one axis between a point at `f` (in [0, 1)) inside its cell and the cell
// `delta` cells away, in cells: delta − f beyond it, f − 1 − delta before it, 0 in it (the
// other two terms are then negative). Without branches: a wide search tests some 40 voxels
// a query.
double cellGap(std::int32_t delta, double f) {
  const auto d = static_cast<double>(delta);
  return std::max({0.0, d - f, f - 1.0 - d});
}

// Calls visit(dx, dy, dz) for the 26 neighbours of a query's voxel whose box may lie
// within the radius (√limit_sq voxels; the visitor may shrink limit_sq) of the query at
// `fraction` inside its voxel, in lexicographic order (the shell loop's): only the sides
// whose face lies within the radius when they are reached. The radius only shrinks, so a
// neighbour left out would fail a test of its box against it anyway.
template <typename Visit>
void visitFirstShell(const Eigen::Vector3d& fraction, const double& limit_sq, Visit&& visit) {
  const auto sides = [&limit_sq](double f, std::int32_t (&deltas)[3]) {
    int count = 0;
    if (f * f <= limit_sq) deltas[count++] = -1;
    deltas[count++] = 0;
    if ((1.0 - f) * (1.0 - f) <= limit_sq) deltas[count++] = 1;
    return count;
  };
  std::int32_t xs[3], ys[3], zs[3];
  const int nx = sides(fraction.x(), xs), ny = sides(fraction.y(), ys), nz = sides(fraction.z(), zs);
  for (int a = 0; a < nx; ++a)
    for (int b = 0; b < ny; ++b)
      for (int c = 0; c < nz; ++c) {
        if (xs[a] == 0 && ys[b] == 0 && zs[c] == 0) continue;
        const double gx = cellGap(xs[a], fraction.x()), gy = cellGap(ys[b], fraction.y()),
                     gz = cellGap(zs[c], fraction.z());
        if (gx * gx + gy * gy + gz * gz > limit_sq) continue;
        visit(xs[a], ys[b], zs[c]);
      }
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
      // A new block's box starts empty; its first point, this one, is always accepted.
      block_low_.resize(blocks_.size(), Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()));
      block_high_.resize(blocks_.size(), Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity()));
    }
    if (counts[voxel] >= max_points_per_voxel_) continue;
    ++counts[voxel];
    accepted.emplace_back(voxel, p);
    const std::uint32_t block = voxel_block_[voxel];
    block_low_[block] = block_low_[block].cwiseMin(point);
    block_high_[block] = block_high_[block].cwiseMax(point);
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
  block_voxel_keys_.resize(block_voxels_.size());
  for (std::size_t k = 0; k < block_voxels_.size(); ++k) block_voxel_keys_[k] = table_.key(block_voxels_[k]);
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
  // The query's own voxel first (shell 0). Where it is empty, the search goes by the
  // blocks of 4³ voxels its box meets: 35-39 % of the ICP's searches on the stress
  // benchmark's lab and rooms find nothing (parts of a scan the map never saw), and where
  // no block meets the box no voxel does; where some do, their voxels are read in a run.
  // A few block lookups instead of one for each of the up to 124 positions round the query.
  const std::uint32_t own_index = table_.find(own);
  if (own_index != VoxelTable::kMissing) {
    const double next_radius = visit(own_index);
    limit_sq = next_radius * next_radius * inverse_size_ * inverse_size_;
  } else if (max_shell <= kBlock) {
    const VoxelKey first = blockOf(low), last = blockOf(high);
    std::array<std::uint32_t, 27> met{};
    std::size_t count = 0;
    for (std::int32_t bx = first.x; bx <= last.x; ++bx)
      for (std::int32_t by = first.y; by <= last.y; ++by)
        for (std::int32_t bz = first.z; bz <= last.z; ++bz) {
          const std::uint32_t block = blocks_.find({bx, by, bz});
          if (block != VoxelTable::kMissing && count < met.size()) met[count++] = block;
        }
    if (count == 0) return;
    // A box of at most 5³ voxels meets at most 2³ blocks (a wider one, of within(), goes on
    // by shells below).
    if (max_shell <= 2) {
      for (std::size_t b = 0; b < count; ++b) {
        for (std::uint32_t k = block_begin_[met[b]]; k < block_begin_[met[b] + 1]; ++k) {
          const VoxelKey& at = block_voxel_keys_[k];
          if (at.x < low.x || at.x > high.x || at.y < low.y || at.y > high.y || at.z < low.z || at.z > high.z) continue;
          const double gx = cellGap(at.x - own.x, fraction.x()), gy = cellGap(at.y - own.y, fraction.y()),
                       gz = cellGap(at.z - own.z, fraction.z());
          if (gx * gx + gy * gy + gz * gz > limit_sq) continue;
          const double next_radius = visit(block_voxels_[k]);
          limit_sq = next_radius * next_radius * inverse_size_ * inverse_size_;
        }
      }
      return;
    }
  }
  // Where that leaves a radius of a voxel or less (the fine stage's gates, and most
  // searches of two voxels), the rest lies among the neighbours visitFirstShell leaves,
  // visited in the shell loop's order below.
  if (max_shell <= 1 || limit_sq <= 1.0) {
    if (max_shell >= 1) visitFirstShell(fraction, limit_sq, visitKey);
    return;
  }
  for (std::int32_t k = 1; k <= max_shell; ++k) {
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
    // A point within a voxel of the query: the rest lies among the 26 voxels round its own
    // (some 40 voxels of the blocks the radius still overlaps would be tested otherwise).
    if (limit_sq <= 1.0) {
      visitFirstShell(fraction, limit_sq, [&](std::int32_t dx, std::int32_t dy, std::int32_t dz) {
        const std::uint32_t voxel = table_.find({own.x + dx, own.y + dy, own.z + dz});
        if (voxel == VoxelTable::kMissing) return;
        const double radius_now = visit(voxel);
        limit_sq = radius_now * radius_now * inverse_size_ * inverse_size_;
      });
      return;
    }
  }
  const auto visitBlock = [&](std::int32_t bx, std::int32_t by, std::int32_t bz) {
    const VoxelKey key{own_block.x + bx, own_block.y + by, own_block.z + bz};
    if (key.x < low.x || key.x > high.x || key.y < low.y || key.y > high.y || key.z < low.z || key.z > high.z) return;
    const double gx = kBlock * cellGap(bx, block_fraction.x()), gy = kBlock * cellGap(by, block_fraction.y()),
                 gz = kBlock * cellGap(bz, block_fraction.z());
    if (gx * gx + gy * gy + gz * gz > limit_sq) return;
    const std::uint32_t block = blocks_.find(key);
    if (block == VoxelTable::kMissing) return;
    // The box of its points.
    const Eigen::Vector3d outside =
        (block_low_[block] - query).cwiseMax(query - block_high_[block]).cwiseMax(0.0) * inverse_size_;
    if (outside.squaredNorm() > limit_sq) return;
    for (std::uint32_t k = block_begin_[block]; k < block_begin_[block + 1]; ++k) {
      const std::uint32_t voxel = block_voxels_[k];
      if (voxel == own_voxel) continue;
      const VoxelKey& at = block_voxel_keys_[k];
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

std::vector<Point> VoxelHashMap::points() const { return points_; }

}  // namespace mlmap::registration
