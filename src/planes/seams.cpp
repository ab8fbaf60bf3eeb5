#include "seams.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <utility>

#include <Eigen/Eigenvalues>

#include "detector.hpp"
#include "median.hpp"
#include "mlmap/planes/classify.hpp"

namespace mlmap {
namespace {

std::size_t rootOf(std::vector<std::size_t>& parent, std::size_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

void unite(std::vector<std::size_t>& parent, std::size_t a, std::size_t b) {
  a = rootOf(parent, a);
  b = rootOf(parent, b);
  if (a != b) parent[std::max(a, b)] = std::min(a, b);
}

// A block of the patch as the seam search sees it.
struct Sample {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();  // its points' (its cell centre and h without points)
  double along = 0.0;                              // m, the mean along the patch's normal
  double spread = -1.0;                            // m, its points' RMS along it; < 0: fewer than three
  double weight = 1.0;                             // its points (at least one)
};

// A piece's own plane: a least-squares fit to its points (the patch's normal where the
// fit is ill-defined or leaves it by more than κ).
struct PiecePlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double distance(const Eigen::Vector3d& p) const { return normal.dot(p - point); }
};

PiecePlane fitPiece(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
                    const Eigen::Vector3d& origin, double kappa_rad) {
  PointMoments moments;
  for (const std::uint32_t id : blocks) {
    const PointStats stats = grid.pointsOf(id);
    if (!stats.empty()) moments.add(stats, grid.pointsFrameOf(id) - origin);
  }
  PiecePlane plane{normal, origin};
  if (moments.count < 3.0) return plane;
  plane.point = origin + moments.mean();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(moments.covariance());
  const Eigen::Vector3d fitted = solver.eigenvectors().col(0);
  if (solver.eigenvalues()(1) > 1e-4 && std::abs(fitted.dot(normal)) > std::cos(kappa_rad))
    plane.normal = fitted.dot(normal) < 0.0 ? Eigen::Vector3d(-fitted) : fitted;
  return plane;
}

// The share of a patch's pairs of neighbouring blocks whose difference measures its
// surface's roughness (the rest: a seam's, and outliers).
constexpr double kNeighbourQuantile = 0.95;

// The seam search on one patch (its blocks: ascending ids).
class SeamSearch {
 public:
  // `slots`: one entry per block of the grid, all -1; they are again when the search ends.
  SeamSearch(const BlockGrid& grid, const PatchSet& set, std::size_t k, const SeamConfig& config,
             std::vector<std::int32_t>& slots)
      : grid_(grid), blocks_(set.blocks[k]), config_(config),
        min_blocks_(static_cast<std::size_t>(std::max(config.min_blocks, 1))),
        normal_(set.planes[k].normal.normalized()), origin_(set.planes[k].centroid), slots_(slots) {
    for (std::size_t n = 0; n < blocks_.size(); ++n) slots_[blocks_[n]] = static_cast<std::int32_t>(n);
  }
  ~SeamSearch() {
    for (const std::uint32_t id : blocks_) slots_[id] = -1;
  }
  SeamSearch(const SeamSearch&) = delete;
  SeamSearch& operator=(const SeamSearch&) = delete;

  // The pieces (each its blocks, ascending; the largest first), or none where the patch
  // holds no seam.
  std::vector<std::vector<std::uint32_t>> pieces() {
    // Level patches only: the cells cut a wall across its normal, and where a wall lies a
    // cm from a cell boundary its noise tail fills the row of cells in front, whose
    // blocks' means lie 1-2 cm in front of the wall's own (a generated office's wall 1 cm
    // from its cells' boundary came apart at 0.7 cm of spread). A level surface's cells
    // cut it along its plane only.
    if (blocks_.size() < 2 * min_blocks_ || !isLevel(normal_) || !measure()) return {};
    std::vector<std::vector<std::uint32_t>> pieces = piecesFrom(largeGroups());
    if (pieces.size() < 2) return {};
    assignTheRest(pieces);
    std::stable_sort(pieces.begin(), pieces.end(),
                     [&](const auto& a, const auto& b) { return surfaceOf(grid_, a) > surfaceOf(grid_, b); });
    return pieces;
  }

 private:
  std::size_t indexOf(std::uint32_t id) const { return static_cast<std::size_t>(slots_[id]); }
  // Visits the index of every block of the patch in the cells within `radius` of block
  // `n`'s.
  template <typename Visit>
  void forEachNear(std::size_t n, int radius, Visit&& visit) const {
    grid_.forEachNeighbour(grid_.blocks()[blocks_[n]].cell, radius, [&](std::uint32_t other) {
      if (slots_[other] >= 0) visit(static_cast<std::size_t>(slots_[other]));
    });
  }
  // Visits the index of every block of the patch in the cells one apart from block `n`'s
  // (its own included; measure() lists them).
  template <typename Visit>
  void forEachAdjacent(std::size_t n, Visit&& visit) const {
    for (std::size_t k = adjacent_first_[n]; k < adjacent_first_[n + 1]; ++k)
      visit(static_cast<std::size_t>(adjacent_[k]));
  }
  // Whether block `n` may seed or measure: three points or more, spread as one surface's.
  bool measured(std::size_t n) const {
    return samples_[n].spread >= 0.0 && samples_[n].spread <= kOneSurfaceSpread * spread_;
  }
  // Whether it may join a group: as one surface's, or too few points to tell.
  bool joinable(std::size_t n) const { return samples_[n].spread <= kOneSurfaceSpread * spread_; }

  // The blocks' samples, the patch's spread and the step; false where they are not measured.
  bool measure() {
    samples_.resize(blocks_.size());
    std::vector<float> spreads;
    for (std::size_t n = 0; n < blocks_.size(); ++n) {
      const std::uint32_t id = blocks_[n];
      const PointStats stats = grid_.pointsOf(id);
      Sample& sample = samples_[n];
      sample.mean = stats.empty() ? Eigen::Vector3d(grid_.blocks()[id].point.cast<double>())
                                  : Eigen::Vector3d(grid_.pointsFrameOf(id) + stats.mean());
      sample.along = normal_.dot(sample.mean);
      sample.weight = std::max(1.0, static_cast<double>(stats.count));
      if (stats.count >= 3) {
        sample.spread = std::sqrt(std::max(0.0, normal_.dot(stats.scatterMatrix() * normal_) / (stats.count - 1.0)));
        spreads.push_back(static_cast<float>(sample.spread));
      }
    }
    if (spreads.size() < 2 * min_blocks_) return false;
    spread_ = medianOf(spreads);
    if (!(spread_ > 0.0)) return false;
    // How far neighbouring blocks of one surface lie apart along the normal: their points'
    // spread says it for the noise alone, but real surfaces are not that smooth from
    // block to block (registered views a cm or two apart, a scanner's calibration,
    // waviness, an elevation map's smoothing): the 95th percentile of the differences
    // between the patch's neighbouring blocks says it for the surface. On level patches of
    // bench/real_data.py's scans at 5 cm cells it is 1.1-4 times the points' spread
    // (3DTK's floor 1.4 cm against 0.5, Bobkov's ceiling 1.2 against 0.3, ANYmal's landing
    // 0.5 against 0.1); cut at three spreads instead, 3DTK's floor kept 40 % on its
    // patch instead of 96, the ANYmal landing 72 % instead of 100, three of the tilted
    // steps' blocks lost theirs. On the simulated offices it is 0.9-1.1 times the spread
    // (a seam between two desks is under 1 % of a patch's pairs).
    // Each block's neighbours (cells one apart, its own included), once: the groups' growth
    // walks them twice per block.
    adjacent_first_.assign(1, 0);
    adjacent_.clear();
    for (std::size_t n = 0; n < blocks_.size(); ++n) {
      forEachNear(n, 1, [&](std::size_t m) { adjacent_.push_back(static_cast<std::uint32_t>(m)); });
      adjacent_first_.push_back(adjacent_.size());
    }
    std::vector<float> differences;
    for (std::size_t n = 0; n < blocks_.size(); ++n) {
      if (!measured(n)) continue;
      forEachAdjacent(n, [&](std::size_t m) {
        if (m > n && measured(m))
          differences.push_back(static_cast<float>(std::abs(samples_[m].along - samples_[n].along)));
      });
    }
    if (differences.size() < 2 * min_blocks_) return false;
    const auto high =
        differences.begin() + static_cast<long>(kNeighbourQuantile * static_cast<double>(differences.size()));
    std::nth_element(differences.begin(), high, differences.end());
    step_ = kSeamStep * std::max<double>(spread_, *high);
    return true;
  }

  // Groups grown from the blocks whose points spread least (one surface's, most surely):
  // a block joins where its mean lies within the step of the mean (by points) of the
  // group's blocks round the block it is reached from, as that one joined, so that a block
  // across the seam, halfway between the surfaces, may join one side but carries no group
  // across to the other. Compared with those neighbours, not with the group's plane: the
  // patch's normal leans between the surfaces (two desks side by side: 1.1° off level, 2.6 cm
  // over one desk). Blocks of one or two points join but seed none (a coarse scan's desk at 5 cm cells: 45 % of its
  // blocks; without them its groups stayed pieces a third of its size). Returns the
  // groups as large as a patch must be, their ids ascending.
  std::vector<std::vector<std::uint32_t>> largeGroups() const {
    std::vector<std::size_t> order;
    for (std::size_t n = 0; n < blocks_.size(); ++n)
      if (measured(n)) order.push_back(n);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return samples_[a].spread < samples_[b].spread; });
    std::vector<int> group_of(blocks_.size(), -1);
    std::vector<double> local(blocks_.size(), 0.0);  // as each block joined: its group's mean round it
    std::vector<std::vector<std::uint32_t>> large;
    std::vector<std::uint32_t> members;
    std::vector<std::size_t> frontier;
    int group = 0;
    for (const std::size_t seed : order) {
      if (group_of[seed] >= 0) continue;
      ++group;
      group_of[seed] = group;
      members.clear();
      frontier.assign(1, seed);
      while (!frontier.empty()) {
        const std::size_t n = frontier.back();
        frontier.pop_back();
        members.push_back(blocks_[n]);
        double along = 0.0, weight = 0.0;
        forEachAdjacent(n, [&](std::size_t q) {
          if (group_of[q] != group) return;
          along += samples_[q].weight * samples_[q].along;
          weight += samples_[q].weight;
        });
        local[n] = along / weight;
        forEachAdjacent(n, [&](std::size_t m) {
          if (group_of[m] >= 0 || !joinable(m) || std::abs(samples_[m].along - local[n]) > step_) return;
          group_of[m] = group;
          frontier.push_back(m);
        });
      }
      if (members.size() >= min_blocks_ &&
          surfaceOf(grid_, members) * grid_.cellSize() * grid_.cellSize() >= config_.min_area) {
        std::sort(members.begin(), members.end());
        large.push_back(members);
      }
    }
    return large;
  }

  // Two groups side by side are two surfaces where they meet a step apart: blocks of the
  // one within two cells of the other's lie further apart along the normal than the step,
  // in the median (across a row of blocks that hold both), over as many pairs as a patch
  // has blocks (a seam is a line: 3DTK's floor at 5 cm cells, ε 9 cm, met a group 6 cm off
  // in 3 pairs).
  // Groups that meet within the step are one surface. The pieces are the joined groups
  // that meet another across a step; a group that meets none says nothing of where it
  // lies, and its blocks go with the rest (assignTheRest).
  std::vector<std::vector<std::uint32_t>> piecesFrom(const std::vector<std::vector<std::uint32_t>>& large) const {
    if (large.size() < 2) return {};
    std::vector<int> large_of(blocks_.size(), -1);
    for (std::size_t a = 0; a < large.size(); ++a)
      for (const std::uint32_t id : large[a]) large_of[indexOf(id)] = static_cast<int>(a);
    std::map<std::pair<int, int>, std::vector<float>> meetings;
    std::map<std::pair<int, int>, std::size_t> stacked;  // pairs of blocks in one cell
    for (std::size_t n = 0; n < blocks_.size(); ++n) {
      const int a = large_of[n];
      if (a < 0) continue;
      const CellIndex cell = grid_.blocks()[blocks_[n]].cell;
      forEachNear(n, 2, [&](std::size_t m) {
        if (large_of[m] <= a) return;
        meetings[{a, large_of[m]}].push_back(static_cast<float>(std::abs(samples_[m].along - samples_[n].along)));
        if (grid_.blocks()[blocks_[m]].cell == cell) ++stacked[{a, large_of[m]}];
      });
    }
    std::vector<std::size_t> joined(large.size());
    std::iota(joined.begin(), joined.end(), std::size_t{0});
    std::vector<char> stepped(large.size(), 0);
    for (auto& [pair, differences] : meetings) {
      // Groups over the same cells are layers, not two surfaces side by side: views of one
      // floor registered apart (3DTK's at 5 cm cells: two layers 6.6 cm apart over 3.8 m²,
      // the upper one cut off and called "other"). The sheets (sheets.hpp) judge layers.
      const auto layered = stacked.find(pair);
      if (differences.size() < min_blocks_ || (layered != stacked.end() && layered->second >= min_blocks_)) continue;
      const auto a = static_cast<std::size_t>(pair.first), b = static_cast<std::size_t>(pair.second);
      if (medianOf(differences) > step_) {
        stepped[a] = stepped[b] = 1;
      } else {
        unite(joined, a, b);
      }
    }
    std::vector<char> cut(large.size(), 0);
    for (std::size_t a = 0; a < large.size(); ++a)
      if (stepped[a] != 0) cut[rootOf(joined, a)] = 1;
    std::vector<std::vector<std::uint32_t>> pieces;
    std::vector<std::size_t> piece_of(large.size(), large.size());
    for (std::size_t a = 0; a < large.size(); ++a) {
      const std::size_t root = rootOf(joined, a);
      if (cut[root] == 0) continue;
      if (piece_of[root] == large.size()) {
        piece_of[root] = pieces.size();
        pieces.emplace_back();
      }
      pieces[piece_of[root]].insert(pieces[piece_of[root]].end(), large[a].begin(), large[a].end());
    }
    for (std::vector<std::uint32_t>& piece : pieces) std::sort(piece.begin(), piece.end());
    return pieces;
  }

  // The blocks of no piece: each to the piece whose own plane lies nearest its points,
  // among those with a block within two cells of it (else among all).
  void assignTheRest(std::vector<std::vector<std::uint32_t>>& pieces) const {
    std::vector<PiecePlane> planes;
    for (const std::vector<std::uint32_t>& piece : pieces)
      planes.push_back(fitPiece(grid_, piece, normal_, origin_, config_.kappa_rad));
    std::vector<int> owner(blocks_.size(), -1);
    for (std::size_t p = 0; p < pieces.size(); ++p)
      for (const std::uint32_t id : pieces[p]) owner[indexOf(id)] = static_cast<int>(p);
    std::vector<int> assigned = owner;
    std::vector<char> near(pieces.size());
    for (std::size_t n = 0; n < blocks_.size(); ++n) {
      if (owner[n] >= 0) continue;
      std::fill(near.begin(), near.end(), 0);
      forEachNear(n, 2, [&](std::size_t m) {
        if (owner[m] >= 0) near[static_cast<std::size_t>(owner[m])] = 1;
      });
      const bool any = std::find(near.begin(), near.end(), 1) != near.end();
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t p = 0; p < pieces.size(); ++p) {
        if (any && near[p] == 0) continue;
        const double distance = std::abs(planes[p].distance(samples_[n].mean));
        if (distance < best) {
          best = distance;
          assigned[n] = static_cast<int>(p);
        }
      }
    }
    for (std::vector<std::uint32_t>& piece : pieces) piece.clear();
    for (std::size_t n = 0; n < blocks_.size(); ++n)
      pieces[static_cast<std::size_t>(assigned[n])].push_back(blocks_[n]);
  }

  const BlockGrid& grid_;
  const std::vector<std::uint32_t>& blocks_;
  const SeamConfig& config_;
  std::size_t min_blocks_;
  Eigen::Vector3d normal_;
  Eigen::Vector3d origin_;
  std::vector<Sample> samples_;
  double spread_ = 0.0;  // m, the median of the blocks' points' RMS along the normal
  double step_ = 0.0;    // m, the least difference a seam is
  std::vector<std::int32_t>& slots_;  // per block of the grid, its index in blocks_ (-1: none)
  std::vector<std::size_t> adjacent_first_;  // per block, where its neighbours start in adjacent_
  std::vector<std::uint32_t> adjacent_;
};

}  // namespace

std::size_t splitAtSeams(const BlockGrid& grid, PatchSet& set, const SeamConfig& config,
                         std::vector<std::uint8_t>* landings) {
  const std::size_t count = set.planes.size();
  const auto searched = [&](std::size_t k) {
    const PlaneClass label = set.planes[k].label;
    return label != PlaneClass::Floor && label != PlaneClass::Ceiling;
  };
  // Each patch's search reads the set only: all of them first, on the threads, each with
  // its own slots.
  std::vector<std::vector<std::vector<std::uint32_t>>> pieces_of(count);
#pragma omp parallel num_threads(teamSize(config.threads)) if (count > 1 && config.threads != 1)
  {
    std::vector<std::int32_t> slots(grid.size(), -1);
#pragma omp for schedule(dynamic, 1)
    for (std::int64_t k = 0; k < static_cast<std::int64_t>(count); ++k) {
      const auto patch = static_cast<std::size_t>(k);
      if (searched(patch)) pieces_of[patch] = SeamSearch(grid, set, patch, config, slots).pieces();
    }
  }
  std::size_t cut = 0;
  for (std::size_t k = 0; k < count; ++k) {
    std::vector<std::vector<std::uint32_t>>& pieces = pieces_of[k];
    if (pieces.empty()) continue;
    ++cut;
    const Plane patch = set.planes[k];
    const CandidatePlane reference{patch.normal.cast<float>(), patch.centroid.cast<float>()};
    const int raster_step = set.outline_frames[k].step;
    for (std::size_t n = 0; n < pieces.size(); ++n) {
      const std::size_t slot = n == 0 ? k : set.planes.size();
      if (n > 0 && landings != nullptr) {
        landings->resize(slot, 0);
        landings->push_back(k < landings->size() ? (*landings)[k] : 0);
      }
      Patch piece;
      piece.blocks = std::move(pieces[n]);
      piece.surface = surfaceOf(grid, piece.blocks);
      piece.raster_step = raster_step;
      Plane described = describePatch(grid, piece, reference, config.kappa_rad, config.noise);
      described.label = patch.label;
      described.source = patch.source;
      described.candidates = patch.candidates;
      const OutlineFrame frame{described.normal, described.centroid, true, raster_step};
      placePatch(set, slot, std::move(described), std::move(piece.blocks), frame);
    }
  }
  return cut;
}

}  // namespace mlmap
