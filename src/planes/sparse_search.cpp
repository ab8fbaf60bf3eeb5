#include "sparse_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <numbers>
#include <numeric>
#include <unordered_map>

#include "median.hpp"
#include "pca_sums.hpp"
#include "smallest_axis.hpp"
#include "sparse_growth.hpp"
#include "unseen_gaps.hpp"

namespace mlmap {
namespace {

// The sparse blocks bucketed in cubes of half the widest gap: the blocks within a
// radius are those of a few rings of buckets.
class SparseIndex {
 public:
  SparseIndex(const std::vector<Eigen::Vector3d>& points, double max_gap) : points_(points), side_(max_gap / 2.0) {
    for (std::uint32_t k = 0; k < points.size(); ++k) buckets_[keyOf(bucketOf(points[k]))].push_back(k);
  }

  // Every other block within `radius` (at most the widest gap).
  template <typename Visit>
  void forEachWithin(std::uint32_t self, double radius, Visit&& visit) const {
    const Eigen::Vector3d& p = points_[self];
    const std::array<std::int64_t, 3> home = bucketOf(p);
    const auto rings = static_cast<std::int64_t>(std::ceil(radius / side_));
    const double squared = radius * radius;
    for (std::int64_t dx = -rings; dx <= rings; ++dx) {
      for (std::int64_t dy = -rings; dy <= rings; ++dy) {
        for (std::int64_t dz = -rings; dz <= rings; ++dz) {
          const auto found = buckets_.find(keyOf({home[0] + dx, home[1] + dy, home[2] + dz}));
          if (found == buckets_.end()) continue;
          for (const std::uint32_t other : found->second) {
            if (other != self && (points_[other] - p).squaredNorm() <= squared) visit(other);
          }
        }
      }
    }
  }

 private:
  std::array<std::int64_t, 3> bucketOf(const Eigen::Vector3d& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x() / side_)), static_cast<std::int64_t>(std::floor(p.y() / side_)),
            static_cast<std::int64_t>(std::floor(p.z() / side_))};
  }
  static std::int64_t keyOf(const std::array<std::int64_t, 3>& b) {
    return (b[0] & 0x1fffff) | ((b[1] & 0x1fffff) << 21) | ((b[2] & 0x1fffff) << 42);
  }

  const std::vector<Eigen::Vector3d>& points_;
  double side_;
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> buckets_;
};

struct LocalPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double thickness = 0.0;  // m, RMS along the normal
  double width = 0.0;      // m, RMS along the plane's narrower axis
};

LocalPlane fitOf(const std::vector<Eigen::Vector3d>& points, const std::vector<std::uint32_t>& ids) {
  PcaSums sums;
  const Eigen::Vector3d origin = points[ids.front()];
  for (const std::uint32_t id : ids) sums.add(points[id] - origin, 1.0);
  const SmallestAxis axis = smallestAxis(sums.covariance());
  return {axis.axis.normalized(), sums.mean() + origin, std::sqrt(axis.smallest_eigenvalue),
          std::sqrt(std::max(0.0, axis.middle_eigenvalue))};
}

bool isLevel(const Eigen::Vector3d& normal) { return std::abs(normal.z()) >= std::cos(std::numbers::pi / 4); }

// The least-squares plane of blocks (grid ids) and their median distance from it.
struct JointFit {
  LocalPlane plane;
  double median_distance = 0.0;
};

JointFit jointFit(const BlockGrid& grid, const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b) {
  std::vector<Eigen::Vector3d> points;
  for (const auto* ids : {&a, &b}) {
    for (const std::uint32_t id : *ids) points.push_back(grid.blocks()[id].point.cast<double>());
  }
  std::vector<std::uint32_t> all(points.size());
  std::iota(all.begin(), all.end(), 0U);
  JointFit fit{fitOf(points, all), 0.0};
  std::vector<float> distances;
  for (const Eigen::Vector3d& p : points) distances.push_back(static_cast<float>(std::abs(fit.plane.normal.dot(p - fit.plane.mean))));
  fit.median_distance = medianOf(distances);
  return fit;
}

// Pieces of one sparse wall, apart by more than the widest gap where nothing was seen
// through it (the scan lost a stretch of the wall, a cabinet hid it): one surface, as
// the search's walls are (unseen_gaps.hpp). A piece belongs to the largest's wall where
// the two together are as flat as one region must be, and the pair stays plumb: one
// piece's own plane is too uncertain to measure the other's distance by (PCL's
// room_scan1 at 5 cm cells: two pieces of its far wall, 2.3 m apart, fit planes 10°
// apart).
void joinWallPieces(const BlockGrid& grid, std::vector<SparseSurface>& surfaces, const SparseSearch& config) {
  std::vector<SparseSurface> joined;
  std::vector<std::uint8_t> used(surfaces.size(), 0);
  for (std::size_t a = 0; a < surfaces.size(); ++a) {
    if (used[a] != 0) continue;
    used[a] = 1;
    CandidatePlane plane = surfaces[a].plane;
    std::vector<Patch> pieces{std::move(surfaces[a].patch)};
    std::vector<std::uint32_t> wall = pieces.front().blocks;
    for (std::size_t b = a + 1; b < surfaces.size() && !isLevel(plane.normal.cast<double>()); ++b) {
      if (used[b] != 0 || isLevel(surfaces[b].plane.normal.cast<double>())) continue;
      const JointFit fit = jointFit(grid, wall, surfaces[b].patch.blocks);
      if (fit.median_distance > config.epsilon / 3.0 || !levelOrPlumb(fit.plane.normal, config.max_tilt_rad) ||
          isLevel(fit.plane.normal)) {
        continue;
      }
      used[b] = 1;
      wall.insert(wall.end(), surfaces[b].patch.blocks.begin(), surfaces[b].patch.blocks.end());
      plane.normal = fit.plane.normal.cast<float>();
      plane.point = fit.plane.mean.cast<float>();
      pieces.push_back(std::move(surfaces[b].patch));
    }
    const double cell_area = grid.cellSize() * grid.cellSize();
    joinUnseenGaps(grid, pieces, plane.normal.cast<double>(), plane.point.cast<double>(), config.epsilon,
                   config.min_blocks, config.min_area / cell_area);
    for (Patch& piece : pieces) joined.push_back({plane, std::move(piece)});
  }
  surfaces = std::move(joined);
}

// The blocks the sparse search looks at: no patch's, and no direction, or one from a
// window that held only a few blocks of a lattice at its height (nothing within a cell
// of it: the direction is that line's, not its surface's).
struct SparseBlocks {
  std::vector<std::uint32_t> ids;  // grid ids
  std::vector<Eigen::Vector3d> points;
  std::vector<std::uint8_t> rungs;  // vertical, or a rung of a wall (isWallRung): no level region takes it
};

SparseBlocks sparseBlocks(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                          const std::vector<std::int32_t>& labels, double ladder_gap) {
  const auto& blocks = grid.blocks();
  const double cell = grid.cellSize();
  SparseBlocks sparse;
  for (std::uint32_t id = 0; id < blocks.size(); ++id) {
    if (labels[id] != 0) continue;
    const PlaneBlock& block = blocks[id];
    if (directions[id].squaredNorm() > 0.0F) {
      bool alone = true;
      grid.forEachNeighbour(block.cell, 1, [&](std::uint32_t other) {
        const PlaneBlock& near = blocks[other];
        alone = alone && (other == id || near.bottom > block.top + cell || near.top < block.bottom - cell);
      });
      if (!alone) continue;
    }
    sparse.ids.push_back(id);
    sparse.points.push_back(block.point.cast<double>());
    sparse.rungs.push_back(block.vertical || isWallRung(grid, id, ladder_gap) ? 1 : 0);
  }
  return sparse;
}

// Whether most of the blocks `region` (indices into `sparse`) lie within two cells of a
// patch's block (across, and up within two cells of their extents): the noise tail of
// a surface found, not a surface of its own (3 cm of noise at 5 cm cells leaves a sparse
// layer of blocks a cell in front of a wall, and the simulated offices with it got 1-3
// phantom walls from it). A far surface touches patches at its rim only.
bool besidePatches(const BlockGrid& grid, const SparseBlocks& sparse, const std::vector<std::uint32_t>& region,
                   const std::vector<std::int32_t>& labels) {
  const double reach = 2.0 * grid.cellSize();
  std::size_t beside = 0;
  for (const std::uint32_t k : region) {
    const PlaneBlock& block = grid.blocks()[sparse.ids[k]];
    bool near = false;
    grid.forEachNeighbour(block.cell, 2, [&](std::uint32_t other) {
      const PlaneBlock& next = grid.blocks()[other];
      near = near || (labels[other] != 0 && next.bottom <= block.top + reach && next.top >= block.bottom - reach);
    });
    beside += near ? 1 : 0;
  }
  return 2 * beside > region.size();
}

// Per sparse block, what its neighbourhood (the blocks within `radius`) says.
struct Neighbourhood {
  LocalPlane plane;      // fitted when it holds enough blocks (else a zero normal)
  double nearest = 0.0;  // m, to the nearest block, at most the radius
  double spacing = 0.0;  // m, 1 / √(its blocks per m² of the radius' disc)
};

}  // namespace

std::vector<SparseSurface> findSparseSurfaces(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                                              const std::vector<std::int32_t>& labels, const SparseSearch& config) {
  // A block's nearest neighbour counts within half the gap, and a region needs its blocks
  // more than a cell apart: a gap of two cells or less can keep none (and a tiny one would
  // make the index's buckets overflow its keys).
  if (!(config.max_gap > 2.0 * grid.cellSize())) return {};
  const SparseBlocks sparse = sparseBlocks(grid, directions, labels, config.ladder_gap);
  const std::vector<Eigen::Vector3d>& points = sparse.points;
  if (points.size() < config.min_blocks) return {};
  const double cell = grid.cellSize();
  const SparseIndex index(points, config.max_gap);
  // A block's local plane: the sparse blocks within half the widest gap (a scan's
  // lattice 15 cm wide puts a dozen there, lines 30 cm apart at least two of them).
  const double local_radius = 0.5 * config.max_gap;
  std::vector<Neighbourhood> around(points.size());
  std::vector<std::uint32_t> seeds;
  std::vector<std::uint32_t> near;
  for (std::uint32_t k = 0; k < points.size(); ++k) {
    Neighbourhood& here = around[k];
    here.nearest = local_radius;
    near.assign(1, k);
    index.forEachWithin(k, local_radius, [&](std::uint32_t other) {
      here.nearest = std::min(here.nearest, (points[other] - points[k]).norm());
      near.push_back(other);
    });
    here.spacing = std::sqrt(std::numbers::pi * local_radius * local_radius / static_cast<double>(near.size()));
    if (near.size() < config.min_blocks) continue;
    here.plane = fitOf(points, near);
    // Flat (as thin as a region must lie: a far surface is noisier than the near ones σ
    // is measured on), spread in two directions (one scan line spreads by its noise
    // across; a lattice within the radius by about the spacing), level or plumb.
    if (here.plane.thickness <= config.epsilon / 3.0 && here.plane.width >= 0.5 * std::max(cell, here.nearest) &&
        levelOrPlumb(here.plane.normal, config.max_tilt_rad)) {
      seeds.push_back(k);
    }
  }
  // The flattest first.
  std::stable_sort(seeds.begin(), seeds.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return around[a].plane.thickness < around[b].plane.thickness; });
  std::vector<std::uint8_t> taken(points.size(), 0);
  std::vector<std::uint8_t> tried(points.size(), 0);    // in a region refused: would seed the same region again
  std::vector<std::uint32_t> in_region(points.size(), 0);  // the number of the region a block was last grown into
  std::uint32_t regions = 0;
  std::vector<SparseSurface> surfaces;
  for (const std::uint32_t seed : seeds) {
    if (taken[seed] != 0 || tried[seed] != 0) continue;
    LocalPlane plane = around[seed].plane;
    const bool level = isLevel(plane.normal);
    const auto fits = [&](std::uint32_t k) {
      return taken[k] == 0 && !(level && sparse.rungs[k] != 0) &&
             std::abs(plane.normal.dot(points[k] - plane.mean)) <= config.epsilon;
    };
    if (!fits(seed)) continue;
    // Grown block by block across gaps up to the widest, the plane refitted each time
    // the region doubles.
    const std::uint32_t number = ++regions;
    std::vector<std::uint32_t> region{seed};
    in_region[seed] = number;
    std::deque<std::uint32_t> queue{seed};
    std::size_t refit_at = 16;
    while (!queue.empty()) {
      const std::uint32_t k = queue.front();
      queue.pop_front();
      index.forEachWithin(k, config.max_gap, [&](std::uint32_t other) {
        if (in_region[other] == number || !fits(other)) return;
        in_region[other] = number;
        region.push_back(other);
        queue.push_back(other);
      });
      if (region.size() >= refit_at) {
        plane = fitOf(points, region);
        refit_at *= 2;
      }
    }
    plane = fitOf(points, region);
    // The region's blocks off its final plane return to the pool.
    std::erase_if(region, [&](std::uint32_t k) { return std::abs(plane.normal.dot(points[k] - plane.mean)) > config.epsilon; });
    const auto refuse = [&] {
      for (const std::uint32_t k : region) tried[k] = 1;
    };
    if (region.size() < config.min_blocks) {
      refuse();
      continue;
    }
    plane = fitOf(points, region);
    std::vector<float> distances;
    std::vector<float> nearest;
    std::vector<float> spacings;
    double surface = 0.0;
    for (const std::uint32_t k : region) {
      distances.push_back(static_cast<float>(std::abs(plane.normal.dot(points[k] - plane.mean))));
      nearest.push_back(static_cast<float>(around[k].nearest));
      spacings.push_back(static_cast<float>(around[k].spacing));
      surface += grid.blocks()[sparse.ids[k]].surface;
    }
    const double region_nearest = medianOf(nearest);
    // As flat as a surface (the median distance of a level plane's blocks, Detector::
    // liesOnPlane: a heap filling the slab puts it at ε / 2), sparser than the grid (a
    // dense one the search had), level or plumb, two-dimensional, large enough, and not
    // a found surface's noise tail.
    if (medianOf(distances) > config.epsilon / 3.0 || region_nearest <= cell ||
        !levelOrPlumb(plane.normal, config.max_tilt_rad) || plane.width < region_nearest ||
        surface * cell * cell < config.min_area || besidePatches(grid, sparse, region, labels)) {
      refuse();
      continue;
    }
    SparseSurface found;
    found.plane.normal = plane.normal.cast<float>();
    found.plane.point = plane.mean.cast<float>();
    for (const std::uint32_t k : region) {
      taken[k] = 1;
      found.patch.blocks.push_back(sparse.ids[k]);
    }
    std::sort(found.patch.blocks.begin(), found.patch.blocks.end());
    found.patch.surface = surface;
    // Its area and outline on a raster coarse enough that neighbouring blocks fill it:
    // cells 1.5 times their spacing (a lattice turned to the raster steps by up to
    // √2 times its spacing along a raster axis, on average by less).
    found.patch.raster_step = std::max(1, static_cast<int>(std::ceil(1.5 * medianOf(spacings) / cell)));
    surfaces.push_back(std::move(found));
  }
  const auto larger = [](const SparseSurface& a, const SparseSurface& b) { return a.patch.surface > b.patch.surface; };
  std::stable_sort(surfaces.begin(), surfaces.end(), larger);
  joinWallPieces(grid, surfaces, config);
  std::stable_sort(surfaces.begin(), surfaces.end(), larger);
  return surfaces;
}

}  // namespace mlmap
