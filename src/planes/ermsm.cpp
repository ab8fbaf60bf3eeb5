#include "mlmap/planes/ermsm.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>

#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/classify.hpp"
#include "mlmap/planes/direction_vectors.hpp"
#include "mlmap/planes/patches.hpp"
#include "pca_sums.hpp"
#include "plane_scorer.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// Each candidate draws from its own generator, seeded from the run's seed and the
// candidate's number: the same candidates at any thread count.
std::uint64_t candidateSeed(std::uint64_t seed, std::uint64_t number) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * (number + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

struct Candidate {
  CandidatePlane plane;
  PlaneScore score;
  std::array<std::uint32_t, 3> seeds{};
  int multiplicity = 1;  // candidates drawn that re-found this one
  bool stale = false;    // blocks were taken since it was scored
};

struct Draw {
  std::optional<Candidate> candidate;
  int duplicate_of = -1;  // index of a listed candidate whose plane all three seeds match
};

class Detector {
 public:
  Detector(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
           const ErmsmConfig& config)
      : grid_(grid),
        directions_(directions),
        config_(config),
        scorer_(grid, directions, config.epsilon, radians(config.kappa_deg)),
        cos_theta_(static_cast<float>(std::cos(radians(config.theta_deg)))),
        min_score_(config.min_area / (grid.cellSize() * grid.cellSize())) {
    rebuildSeedable();
  }

  std::vector<Plane> run(ErmsmStats& stats);
  // The patch id of every block (0 for none), by block id.
  const std::vector<std::int32_t>& labels() const { return labels_; }
  // After classification: one patch per floor and per ceiling.
  std::vector<Plane> mergeLevels(const std::vector<Plane>& planes);

 private:
  void rebuildSeedable();
  Draw draw(std::uint64_t number) const;
  void refit(Candidate& candidate) const;
  std::optional<std::size_t> bestCandidate();
  bool accept(std::size_t index, std::vector<Plane>& planes);
  std::vector<std::uint32_t> withEdges(std::vector<std::uint32_t> matching, const CandidatePlane& plane) const;
  Plane describePatch(const Patch& patch, const CandidatePlane& reference) const;
  std::vector<Plane> mergeCoplanar(const std::vector<Plane>& planes);
  std::vector<Plane> mergeGroups(const std::vector<Plane>& planes, const std::vector<std::size_t>& roots);
  double directionSpread(const std::vector<std::uint32_t>& ids, const CandidatePlane& plane) const;
  bool isThin(const Patch& patch, const CandidatePlane& plane) const;

  const BlockGrid& grid_;
  const std::vector<Eigen::Vector3f>& directions_;
  const ErmsmConfig& config_;
  PlaneScorer scorer_;
  float cos_theta_;
  double min_score_;
  std::vector<std::uint32_t> seedable_;  // untaken blocks with a direction vector
  std::vector<Candidate> candidates_;    // L_c
  std::size_t unlisted_ = 0;             // drawn candidates too small to ever be accepted
  std::vector<std::int32_t> labels_ = std::vector<std::int32_t>(grid_.size(), 0);
  std::vector<std::vector<std::uint32_t>> plane_blocks_;  // block ids of each patch
  std::int32_t accepted_ = 0;
  std::int32_t since_acceptance_ = 0;
  ErmsmStats* stats_ = nullptr;
};

void Detector::rebuildSeedable() {
  seedable_.clear();
  for (std::uint32_t id = 0; id < grid_.size(); ++id) {
    if (!scorer_.taken(id) && directions_[id].squaredNorm() > 0.0F) seedable_.push_back(id);
  }
}

// newCandidates of Algorithm 1: a random block and two more within radius r whose
// direction vectors agree within θ; the plane through their barycentre with the
// mean of their directions as normal (Fig. 5c).
Draw Detector::draw(std::uint64_t number) const {
  Draw result;
  std::mt19937_64 random(candidateSeed(config_.seed, number));
  constexpr int kAttempts = 8;
  std::vector<std::uint32_t> neighbours;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    const std::uint32_t first = seedable_[std::uniform_int_distribution<std::size_t>(0, seedable_.size() - 1)(random)];
    const Eigen::Vector3f& first_direction = directions_[first];
    neighbours.clear();
    grid_.forEachNeighbour(grid_.blocks()[first].cell, config_.radius, [&](std::uint32_t id) {
      if (id != first && !scorer_.taken(id) && std::abs(directions_[id].dot(first_direction)) >= cos_theta_) {
        neighbours.push_back(id);
      }
    });
    if (neighbours.size() < 2) continue;
    std::uniform_int_distribution<std::size_t> pick(0, neighbours.size() - 1);
    const std::uint32_t second = neighbours[pick(random)];
    std::uint32_t third = neighbours[pick(random)];
    if (third == second) third = neighbours[(std::find(neighbours.begin(), neighbours.end(), second) - neighbours.begin() + 1) % neighbours.size()];
    if (std::abs(directions_[second].dot(directions_[third])) < cos_theta_) continue;
    Candidate candidate;
    candidate.seeds = {first, second, third};
    Eigen::Vector3f normal = Eigen::Vector3f::Zero();
    Eigen::Vector3f point = Eigen::Vector3f::Zero();
    for (const std::uint32_t id : candidate.seeds) {
      const Eigen::Vector3f& direction = directions_[id];
      normal += direction.dot(first_direction) < 0.0F ? Eigen::Vector3f(-direction) : direction;
      point += grid_.blocks()[id].point;
    }
    candidate.plane.normal = orientConsistently(normal);
    candidate.plane.point = point / 3.0F;
    // A candidate whose seeds all match a listed plane re-finds it: count it there.
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
      const CandidatePlane& listed = candidates_[k].plane;
      if (scorer_.matches(first, listed) && scorer_.matches(second, listed) &&
          scorer_.matches(third, listed)) {
        result.duplicate_of = static_cast<int>(k);
        return result;
      }
    }
    refit(candidate);
    result.candidate = candidate;
    return result;
  }
  return result;
}

// Algorithm 2: refit the normal (and the point) by PCA over the matched blocks
// until the score gains less than the threshold; a refit that loses is undone.
void Detector::refit(Candidate& candidate) const {
  candidate.score = scorer_.score(candidate.plane);
  for (int iteration = 0; iteration < config_.max_refits; ++iteration) {
    const PlaneScore& score = candidate.score;
    if (score.pca.weight < 3.0) return;
    const Eigen::Vector3d mean = score.pca.mean();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(score.pca.covariance());
    Eigen::Vector3f normal = solver.eigenvectors().col(0).cast<float>();
    if (!(normal.squaredNorm() > 0.5F)) return;
    if (normal.dot(candidate.plane.normal) < 0.0F) normal = -normal;
    CandidatePlane refitted{orientConsistently(normal), candidate.plane.point + mean.cast<float>()};
    PlaneScore refitted_score = scorer_.score(refitted);
    const double gain = refitted_score.score - score.score;
    if (gain < 0.0) return;
    candidate.plane = refitted;
    candidate.score = std::move(refitted_score);
    if (gain < config_.refit_gain) return;
  }
}

// bestCandidate of Algorithm 1, lazily: a stale score is an upper bound (taking
// blocks only lowers scores), so only the leader is ever rescored.
std::optional<std::size_t> Detector::bestCandidate() {
  while (!candidates_.empty()) {
    std::size_t best = 0;
    for (std::size_t k = 1; k < candidates_.size(); ++k) {
      if (candidates_[k].score.score > candidates_[best].score.score) best = k;
    }
    Candidate& leader = candidates_[best];
    if (!leader.stale) return best;
    leader.score = scorer_.score(leader.plane);
    leader.stale = false;
    ++stats_->scored;
    if (leader.score.score < min_score_) {
      unlisted_ += static_cast<std::size_t>(leader.multiplicity);
      candidates_.erase(candidates_.begin() + static_cast<long>(best));
    }
  }
  return std::nullopt;
}

Plane Detector::describePatch(const Patch& patch, const CandidatePlane& reference) const {
  Plane plane;
  const double cell_area = grid_.cellSize() * grid_.cellSize();
  // Each patch is refitted on its own blocks, so two tables at slightly different
  // heights keep their own offsets.
  PcaSums pca;
  const Eigen::Vector3d origin = reference.point.cast<double>();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const std::uint32_t id : patch.blocks) {
    const PlaneBlock& block = grid_.blocks()[id];
    centroid += block.point.cast<double>();
    pca.addBlock(block.point.cast<double>() - origin, block.vertical ? 0.5 * (block.top - block.bottom) : 0.0,
                 block.surface);
  }
  Eigen::Vector3d normal = reference.normal.cast<double>();
  Eigen::Vector3d point = origin;
  if (pca.weight >= 3.0) {
    const Eigen::Vector3d mean = pca.mean();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(pca.covariance());
    const Eigen::Vector3d fitted = solver.eigenvectors().col(0);
    // Keep the patch's own fit only where it is well defined and close to the plane's.
    if (solver.eigenvalues()(1) > 1e-4 && std::abs(fitted.dot(normal)) > std::cos(radians(config_.kappa_deg))) {
      normal = fitted;
    }
    point = origin + mean;
  }
  normal = orientConsistently(normal.cast<float>()).cast<double>();
  plane.normal = normal;
  plane.offset = -normal.dot(point);
  plane.centroid = centroid / static_cast<double>(patch.blocks.size());
  plane.area = patch.surface * cell_area;
  plane.block_count = patch.blocks.size();
  double squared = 0.0;
  for (const std::uint32_t id : patch.blocks) {
    const double distance = normal.dot(grid_.blocks()[id].point.cast<double>()) + plane.offset;
    squared += distance * distance;
  }
  plane.rms = std::sqrt(squared / static_cast<double>(patch.blocks.size()));
  // The outline lies on the plane the patch was split on: put it on the patch's own.
  for (const Eigen::Vector3d& corner : patch.outline) {
    plane.outline.push_back(corner - normal * (normal.dot(corner) + plane.offset));
  }
  return plane;
}

// Beyond the paper: blocks on the plane's edges, where a corner or a rim bends
// their direction vectors past κ (or leaves them none), join the plane when they
// touch its matching blocks, lie within ε and point within 2κ of it. Otherwise
// room corners are left over and later form small diagonal "walls".
std::vector<std::uint32_t> Detector::withEdges(std::vector<std::uint32_t> matching,
                                               const CandidatePlane& plane) const {
  std::vector<std::uint8_t> in_plane(grid_.size(), 0);
  for (const std::uint32_t id : matching) in_plane[id] = 1;
  const float cos_edge = static_cast<float>(std::cos(std::min(2.0 * radians(config_.kappa_deg), std::numbers::pi / 2)));
  const auto epsilon = static_cast<float>(config_.epsilon);
  std::vector<std::uint32_t> frontier = matching;
  while (!frontier.empty()) {
    std::vector<std::uint32_t> next;
    for (const std::uint32_t id : frontier) {
      grid_.forEachNeighbour(grid_.blocks()[id].cell, 1, [&](std::uint32_t other) {
        if (in_plane[other] != 0 || scorer_.taken(other)) return;
        const Eigen::Vector3f& direction = directions_[other];
        if (direction.squaredNorm() > 0.0F && std::abs(direction.dot(plane.normal)) < cos_edge) return;
        if (std::abs(plane.normal.dot(grid_.blocks()[other].point - plane.point)) >= epsilon) return;
        in_plane[other] = 1;
        next.push_back(other);
      });
    }
    matching.insert(matching.end(), next.begin(), next.end());
    frontier = std::move(next);
  }
  std::sort(matching.begin(), matching.end());
  return matching;
}

// A patch one cell wide is no surface: it is the fringe of a wall standing on a cell
// boundary (stray points in the next column) or a line of clutter. Its blocks must
// spread across the plane in both directions.
bool Detector::isThin(const Patch& patch, const CandidatePlane& plane) const {
  PcaSums pca;
  for (const std::uint32_t id : patch.blocks) {
    const PlaneBlock& block = grid_.blocks()[id];
    pca.addBlock((block.point - plane.point).cast<double>(),
                 block.vertical ? 0.5 * (block.top - block.bottom) : 0.0, 1.0);
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
  return minor < config_.min_patch_width_cells * grid_.cellSize();
}

double Detector::directionSpread(const std::vector<std::uint32_t>& ids, const CandidatePlane& plane) const {
  double weighted = 0.0;
  double weight = 0.0;
  for (const std::uint32_t id : ids) {
    const double cosine = std::min(1.0F, std::abs(directions_[id].dot(plane.normal)));
    weighted += grid_.blocks()[id].surface * std::acos(cosine);
    weight += grid_.blocks()[id].surface;
  }
  return weight > 0.0 ? weighted / weight * 180.0 / std::numbers::pi : 0.0;
}

// Beyond the paper: patches of one real plane found apart (a refit that tilted a
// little, a wall on a cell boundary) are merged when they are coplanar within ε,
// parallel within κ / 2 and touch on the grid.
std::vector<Plane> Detector::mergeCoplanar(const std::vector<Plane>& planes) {
  const std::size_t count = planes.size();
  std::vector<std::size_t> group(count);
  for (std::size_t k = 0; k < count; ++k) group[k] = k;
  auto root = [&](std::size_t k) {
    while (group[k] != k) k = group[k] = group[group[k]];
    return k;
  };
  const double cos_parallel = std::cos(0.5 * radians(config_.kappa_deg));
  // Pieces closer than a table leg's width are one surface.
  const int touch_radius = std::max(2, static_cast<int>(std::ceil(0.3 / grid_.cellSize())));
  for (std::size_t a = 0; a < count; ++a) {
    for (std::size_t b = a + 1; b < count; ++b) {
      const Plane& first = planes[a];
      const Plane& second = planes[b];
      if (std::abs(first.normal.dot(second.normal)) < cos_parallel) continue;
      if (std::abs(first.normal.dot(second.centroid) + first.offset) >= config_.epsilon ||
          std::abs(second.normal.dot(first.centroid) + second.offset) >= config_.epsilon) {
        continue;
      }
      bool touching = false;
      for (const std::uint32_t id : plane_blocks_[a]) {
        grid_.forEachNeighbour(grid_.blocks()[id].cell, touch_radius, [&](std::uint32_t other) {
          if (labels_[other] == second.id) touching = true;
        });
        if (touching) break;
      }
      if (touching) group[root(b)] = root(a);
    }
  }
  std::vector<std::size_t> roots(count);
  for (std::size_t k = 0; k < count; ++k) roots[k] = root(k);
  return mergeGroups(planes, roots);
}

// Floor and ceiling patches are one level each, however far apart (a floor seen
// between furniture, a ceiling either side of a beam): one patch per class.
std::vector<Plane> Detector::mergeLevels(const std::vector<Plane>& planes) {
  std::vector<std::size_t> roots(planes.size());
  for (std::size_t k = 0; k < planes.size(); ++k) {
    roots[k] = k;
    if (planes[k].label != PlaneClass::Floor && planes[k].label != PlaneClass::Ceiling) continue;
    for (std::size_t first = 0; first < k; ++first) {
      if (planes[first].label == planes[k].label) {
        roots[k] = first;
        break;
      }
    }
  }
  return mergeGroups(planes, roots);
}

// Merges the planes that share a root (the root's index is the smallest of its
// group); ids are renumbered in order and the block labels follow.
std::vector<Plane> Detector::mergeGroups(const std::vector<Plane>& planes, const std::vector<std::size_t>& roots) {
  const std::size_t count = planes.size();
  auto root = [&](std::size_t k) { return roots[k]; };
  std::vector<Plane> merged;
  std::vector<std::int32_t> new_id(count, 0);
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t head = root(k);
    if (head != k) continue;
    std::vector<std::uint32_t> blocks;
    for (std::size_t member = 0; member < count; ++member) {
      if (root(member) == head) blocks.insert(blocks.end(), plane_blocks_[member].begin(), plane_blocks_[member].end());
    }
    std::sort(blocks.begin(), blocks.end());
    const Plane& largest = planes[k];
    const CandidatePlane reference{largest.normal.cast<float>(), largest.centroid.cast<float>()};
    Patch patch;
    patch.blocks = blocks;
    for (const std::uint32_t id : blocks) patch.surface += grid_.blocks()[id].surface;
    const auto outlined = splitIntoPatches(grid_, blocks, largest.normal, largest.centroid);
    if (!outlined.empty()) patch.outline = outlined.front().outline;
    Plane plane = describePatch(patch, reference);
    plane.id = static_cast<std::int32_t>(merged.size() + 1);
    plane.source = largest.source;
    plane.candidates = largest.candidates;
    for (std::size_t member = 0; member < count; ++member) {
      if (root(member) == head) new_id[member] = plane.id;
    }
    plane.label = largest.label;
    merged.push_back(std::move(plane));
  }
  std::vector<std::vector<std::uint32_t>> merged_blocks(merged.size());
  for (std::size_t k = 0; k < count; ++k) {
    auto& blocks = merged_blocks[static_cast<std::size_t>(new_id[k] - 1)];
    blocks.insert(blocks.end(), plane_blocks_[k].begin(), plane_blocks_[k].end());
  }
  for (auto& blocks : merged_blocks) std::sort(blocks.begin(), blocks.end());
  plane_blocks_ = std::move(merged_blocks);
  for (std::int32_t& label : labels_) {
    if (label > 0) label = new_id[static_cast<std::size_t>(label - 1)];
  }
  return merged;
}

// Lines 8–11 of Algorithm 1: the matching blocks leave the map (split into
// connected patches), and candidates seeded on them leave the list.
bool Detector::accept(std::size_t index, std::vector<Plane>& planes) {
  const Candidate accepted = candidates_[index];
  const std::vector<std::uint32_t> strict = scorer_.matching(accepted.plane);
  // A curved surface (a pillar) fits planes only facet by facet, with directions
  // fanning out across each facet: a real plane's blocks agree with its normal.
  if (directionSpread(strict, accepted.plane) > config_.max_direction_spread_deg) {
    unlisted_ += static_cast<std::size_t>(accepted.multiplicity);
    candidates_.erase(candidates_.begin() + static_cast<long>(index));
    return false;
  }
  const std::vector<std::uint32_t> matching = withEdges(strict, accepted.plane);
  const auto patches = splitIntoPatches(grid_, matching, accepted.plane.normal.cast<double>(),
                                        accepted.plane.point.cast<double>());
  const double cell_area = grid_.cellSize() * grid_.cellSize();
  ++accepted_;
  bool kept = false;
  for (const Patch& patch : patches) {
    if (patch.surface * cell_area < config_.min_patch_area ||
        patch.blocks.size() < static_cast<std::size_t>(config_.min_patch_blocks) ||
        isThin(patch, accepted.plane)) {
      continue;
    }
    Plane plane = describePatch(patch, accepted.plane);
    plane.id = static_cast<std::int32_t>(planes.size() + 1);
    plane.source = accepted_;
    plane.candidates = since_acceptance_;
    for (const std::uint32_t id : patch.blocks) {
      scorer_.take(id);
      labels_[id] = plane.id;
    }
    plane_blocks_.push_back(patch.blocks);
    planes.push_back(std::move(plane));
    kept = true;
  }
  if (!kept) {
    --accepted_;
    unlisted_ += static_cast<std::size_t>(accepted.multiplicity);
    candidates_.erase(candidates_.begin() + static_cast<long>(index));
    return false;
  }
  std::vector<Candidate> remaining;
  for (Candidate& candidate : candidates_) {
    const bool seeded_on_taken = scorer_.taken(candidate.seeds[0]) || scorer_.taken(candidate.seeds[1]) ||
                                 scorer_.taken(candidate.seeds[2]);
    if (seeded_on_taken) continue;
    candidate.stale = true;
    remaining.push_back(std::move(candidate));
  }
  candidates_ = std::move(remaining);
  rebuildSeedable();
  since_acceptance_ = 0;
  return true;
}

std::vector<Plane> Detector::run(ErmsmStats& stats) {
  stats_ = &stats;
  std::vector<Plane> planes;
  const int batch = std::max(1, config_.batch_size);
#ifdef _OPENMP
  const int threads = config_.threads > 0 ? config_.threads : omp_get_max_threads();
#endif
  std::uint64_t generated = 0;
  int empty_batches = 0;
  while (generated < static_cast<std::uint64_t>(config_.max_candidates) && seedable_.size() >= 3) {
    std::vector<Draw> draws(static_cast<std::size_t>(batch));
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int k = 0; k < batch; ++k) draws[static_cast<std::size_t>(k)] = draw(generated + static_cast<std::uint64_t>(k));
    generated += static_cast<std::uint64_t>(batch);
    bool any = false;
    for (Draw& drawn : draws) {
      if (drawn.duplicate_of >= 0) {
        ++candidates_[static_cast<std::size_t>(drawn.duplicate_of)].multiplicity;
      } else if (!drawn.candidate) {
        continue;
      } else if (drawn.candidate->score.score < min_score_) {
        ++unlisted_;
        ++stats.scored;
      } else {
        candidates_.push_back(std::move(*drawn.candidate));
        ++stats.scored;
      }
      any = true;
      ++stats.candidates;
      ++since_acceptance_;
    }
    // No three neighbouring blocks agree any more: no candidate can be formed.
    empty_batches = any ? 0 : empty_batches + 1;
    if (empty_batches >= 4 || since_acceptance_ >= config_.max_idle_candidates) break;
    // Lines 5–12: accept the best candidate while eq. 10 says a better one is
    // unlikely to have been overlooked.
    while (const auto best = bestCandidate()) {
      const Candidate& leader = candidates_[*best];
      std::size_t listed = unlisted_;
      for (const Candidate& candidate : candidates_) listed += static_cast<std::size_t>(candidate.multiplicity);
      const double ratio = std::min(1.0, leader.score.score / std::max(leader.score.similar, 1e-9));
      const double probability = 1.0 - std::pow(1.0 - std::pow(ratio, config_.acceptance_exponent), static_cast<double>(listed));  // eq. 6, 10
      if (probability < config_.min_probability) break;
      accept(*best, planes);
      if (seedable_.size() < 3) break;
    }
  }
  stats.accepted = static_cast<std::size_t>(accepted_);
  std::vector<Plane> merged = mergeCoplanar(planes);
  return merged;
}

}  // namespace

PlaneDetection detectPlanes(MLMap& map, const ErmsmConfig& input_config) {
  PlaneDetection detection;
  ErmsmConfig& config = detection.config;
  config = input_config;
  if (config.epsilon <= 0.0) config.epsilon = std::max(map.cellSize(), 0.02);
  for (std::size_t n = 0; n < map.cellCount(); ++n) {
    for (Block& block : map.mutableBlocksAt(n)) block.plane = 0;
  }
  auto start = Clock::now();
  const BlockGrid grid(map);
  DirectionConfig direction_config;
  direction_config.radius = config.radius;
  direction_config.height_tolerance = static_cast<float>(config.epsilon);
  direction_config.threads = config.threads;
  const std::vector<Eigen::Vector3f> directions = directionVectors(grid, direction_config);
  ErmsmStats& stats = detection.stats;
  stats.direction_seconds = secondsSince(start);
  stats.blocks = grid.size();
  stats.blocks_with_direction = static_cast<std::size_t>(
      std::count_if(directions.begin(), directions.end(), [](const Eigen::Vector3f& d) { return d.squaredNorm() > 0.0F; }));

  start = Clock::now();
  Detector detector(grid, directions, config);
  detection.planes = detector.run(stats);
  stats.detection_seconds = secondsSince(start);

  classifyPlanes(detection.planes);
  detection.planes = detector.mergeLevels(detection.planes);
  const std::vector<std::int32_t>& labels = detector.labels();
  for (std::size_t n = 0; n < map.cellCount(); ++n) {
    const auto blocks = map.mutableBlocksAt(n);
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      blocks[k].plane = labels[grid.firstBlockOfCell(n) + k];
      if (blocks[k].plane != 0) ++stats.labelled_blocks;
    }
  }
  return detection;
}

}  // namespace mlmap
