// Algorithm 1 of section V: candidates in batches, the best one accepted while eq. 10
// says a better one is unlikely to have been overlooked; then, beyond the paper, each
// accepted plane split into connected patches, patches of one surface merged, and every
// patch classified. The steps live in their own files: direction_vectors (Fig. 4),
// candidates (newCandidates, Fig. 5c, Algorithm 2), plane_scorer (the score in surface
// units), patch_rules and patches (what an accepted plane keeps), patch_set (merges).
#include "mlmap/planes/ermsm.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>

#include "candidates.hpp"
#include "fill_vector.hpp"
#include "median.hpp"
#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/classify.hpp"
#include "mlmap/planes/direction_vectors.hpp"
#include "mlmap/planes/patches.hpp"
#include "patch_rules.hpp"
#include "patch_set.hpp"
#include "plane_scorer.hpp"
#include "surface_noise.hpp"
#include "unseen_gaps.hpp"

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

// Threads for the passes over the kept patches (descriptions, outlines): maps under
// 100 000 blocks use one, as the scorer's index does. There the passes take a few
// milliseconds, and on a shared machine a parallel region can wait as long for a core.
int patchPassThreads(const BlockGrid& grid, int threads) { return grid.size() < 100000 ? 1 : threads; }
// A patch of fewer blocks has its labels written on one thread.
constexpr std::int64_t kParallelPatchBlocks = 20000;

// The threads an OpenMP region of `threads` (0: OpenMP's default) gets.
int teamSize(int threads) {
#ifdef _OPENMP
  return threads > 0 ? threads : omp_get_max_threads();
#else
  (void)threads;
  return 1;
#endif
}

// The range noise of the map's points: a vertical block keeps the variance of its
// top measurement (section IV), so their median is a measurement's. 1 cm without any.
double rangeNoise(const MLMap& map) {
  std::vector<float> variances;
  for (std::size_t n = 0; n < map.cellCount(); ++n) {
    for (const Block& block : map.blocksAt(n)) {
      if (block.isVertical()) variances.push_back(block.variance);
    }
  }
  if (variances.empty()) return 0.01;
  return std::sqrt(std::max(0.0F, medianOf(variances)));
}

// Whether the map's blocks keep their points' moments (format 3 and later).
bool hasPointStats(const MLMap& map) {
  for (std::size_t n = 0; n < map.cellCount(); ++n) {
    for (const Block& block : map.blocksAt(n)) {
      if (!block.points.empty()) return true;
    }
  }
  return false;
}

class Detector {
 public:
  Detector(const BlockGrid& grid, const DirectionField& field, const ErmsmConfig& config)
      : grid_(grid),
        directions_(field.vectors),
        tilts_(field.tilts),
        config_(config),
        scorer_(grid, field.vectors, config.epsilon, radians(config.kappa_deg), config.threads),
        min_score_(config.min_area / (grid.cellSize() * grid.cellSize())),
        patch_threads_(teamSize(patchPassThreads(grid, config.threads))) {
    patches_.labels.assign(grid.size(), 0);
    FillVector<std::uint8_t> directed(grid.size());
    const auto blocks = static_cast<std::int64_t>(grid.size());
#pragma omp parallel for schedule(static) num_threads(patch_threads_) if (patch_threads_ > 1)
    for (std::int64_t id = 0; id < blocks; ++id) {
      directed[static_cast<std::size_t>(id)] = field.vectors[static_cast<std::size_t>(id)].squaredNorm() > 0.0F ? 1 : 0;
    }
    seedable_ = grid.idsInMapOrder(directed, patch_threads_);
  }

  // Algorithm 1; the patches it leaves, coplanar pieces merged.
  PatchSet run(ErmsmStats& stats);

 private:
  CandidateSource source() const {
    return CandidateSource{grid_, directions_, scorer_, seedable_, config_.radius,
                           static_cast<float>(std::cos(radians(config_.theta_deg))), config_.max_refits,
                           config_.refit_gain};
  }
  std::optional<std::size_t> bestCandidate();
  double acceptanceProbability(const Candidate& leader) const;
  bool noiseExplainsSpread(const CandidatePlane& plane, const std::vector<std::uint32_t>& strict) const;
  bool nearlyLevel(const CandidatePlane& plane) const;
  bool liesOnPlane(const CandidatePlane& plane, const std::vector<std::uint32_t>& strict) const;
  bool accept(std::size_t index);
  void drop(std::size_t index);

  const BlockGrid& grid_;
  const std::vector<Eigen::Vector3f>& directions_;
  const std::vector<float>& tilts_;
  const ErmsmConfig& config_;
  PlaneScorer scorer_;
  double min_score_;
  int patch_threads_;  // for the passes over an accepted plane's blocks
  std::vector<std::uint32_t> seedable_;  // blocks with a direction vector, in map order; taken ones pruned now and then
  std::size_t seedable_taken_ = 0;       // of which taken
  std::vector<Candidate> candidates_;    // L_c
  std::size_t unlisted_ = 0;             // drawn candidates too small to ever be accepted
  PatchSet patches_;
  std::int32_t accepted_ = 0;
  std::int32_t since_acceptance_ = 0;
  ErmsmStats* stats_ = nullptr;
  std::vector<CandidatePlane> refused_;  // accepted planes that kept no patch, since blocks were last taken
  // Per kept patch, what describing it needs: no decision of the search reads a patch's
  // fit, so the patches are described after it, all at once on all threads.
  struct Undescribed {
    CandidatePlane reference;  // the accepted plane it was split from
    double surface;            // surface units
  };
  std::vector<Undescribed> undescribed_;
  void describePatches();
};

// Each patch into its own slot: the same planes at any thread count.
void Detector::describePatches() {
#ifdef _OPENMP
  const int requested = patchPassThreads(grid_, config_.threads);
  const int threads = requested > 0 ? requested : omp_get_max_threads();
#endif
  const double kappa = radians(config_.kappa_deg);
  const auto count = static_cast<std::int64_t>(patches_.planes.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (count > 1)
  for (std::int64_t n = 0; n < count; ++n) {
    const auto k = static_cast<std::size_t>(n);
    Patch patch;
    patch.blocks = std::move(patches_.blocks[k]);
    patch.surface = undescribed_[k].surface;
    Plane described = describePatch(grid_, patch, undescribed_[k].reference, kappa);
    Plane& plane = patches_.planes[k];
    described.id = plane.id;
    described.source = plane.source;
    described.candidates = plane.candidates;
    plane = std::move(described);
    patches_.blocks[k] = std::move(patch.blocks);
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
    if (leader.score.score < min_score_) drop(best);
  }
  return std::nullopt;
}

// Eq. 6 with eq. 10's single-pass probability: P = 1 − (1 − (s_c / s_o)^k)^s, s the
// candidates drawn since the list was last emptied of this plane's rivals.
double Detector::acceptanceProbability(const Candidate& leader) const {
  std::size_t listed = unlisted_;
  for (const Candidate& candidate : candidates_) listed += static_cast<std::size_t>(candidate.multiplicity);
  const double ratio = std::min(1.0, leader.score.score / std::max(leader.score.similar, 1e-9));
  return 1.0 - std::pow(1.0 - std::pow(ratio, config_.acceptance_exponent), static_cast<double>(listed));
}

// A level plane whose blocks' directions spread more than max_direction_spread_deg may
// still be a surface: its blocks scatter in height by the range noise, and where that is
// a good part of a cell (3DTK's ceiling at 5 cm cells: 5.5 cm RMS) their directions
// spread by more than 8° without any curvature. Accepted when the spread is within the
// limit on top of that noise (the two adding in squares). Not for walls: a vertical
// block's direction is uncertain where its window holds a corner or a pillar's turn,
// which is what the spread rule is for (excusing that let 45° facets across the lab's
// corners through).
bool Detector::noiseExplainsSpread(const CandidatePlane& plane, const std::vector<std::uint32_t>& strict) const {
  const double limit = spreadLimit(config_.max_direction_spread_deg, noiseSpread(tilts_, strict, radians(config_.kappa_deg)));
  return !spreadExceeds(grid_, directions_, strict, plane, limit, patch_threads_);
}

// A level plane within max_direction_spread_deg of level needs no direction test, only
// liesOnPlane's: the level surfaces of buildings are (floors, ceilings, desks), and on real
// scans their blocks' directions spread by more than the noise estimate says, because
// what lies on them (papers, keyboards, lamps) tilts the windows. PCL's room_scan1 at
// 5 cm cells: its two desks (4° and 6° off level by their own fits) spread 12-20°, and
// Bobkov's sideboard (3.5°); none was a patch. A plane tilted further (a ramp, a chair's
// back, plane_seg's cinder blocks at 13°) still meets the spread rule. The simulated
// scenes' patches are the same either way (bench/planes_sweep.py, lab and corridor).
bool Detector::nearlyLevel(const CandidatePlane& plane) const {
  return std::abs(plane.normal.z()) >= std::cos(radians(config_.max_direction_spread_deg));
}

// A level plane's blocks must lie on it: their median distance (PlaneBlock::point)
// from it at most ε / 3. Noise of σ ≤ ε / 3 puts it at 0.67 σ or less; a heap of clutter
// filling the slab ±ε round the plane at ε / 2. Direction windows widened over a heap see
// it level on average, so the spread rule alone no longer refuses one. A median, so that
// blocks a chair or a lamp pulls off a table or ceiling do not count. Level planes only:
// a vertical block sits at mid-height, its distance from a tilted plane says nothing.
bool Detector::liesOnPlane(const CandidatePlane& plane, const std::vector<std::uint32_t>& strict) const {
  return medianDistance(grid_, strict, plane) <= config_.epsilon / 3.0;
}

void Detector::drop(std::size_t index) {
  unlisted_ += static_cast<std::size_t>(candidates_[index].multiplicity);
  candidates_.erase(candidates_.begin() + static_cast<long>(index));
}

// Lines 8–11 of Algorithm 1: the matching blocks leave the map (split into
// connected patches), and candidates seeded on them leave the list.
bool Detector::accept(std::size_t index) {
  const Candidate accepted = candidates_[index];
  // Candidates seeded apart often refit to the very same plane: one that kept nothing
  // keeps nothing again until blocks are taken.
  const auto same = [&](const CandidatePlane& plane) {
    return plane.normal == accepted.plane.normal && plane.point == accepted.plane.point;
  };
  if (std::any_of(refused_.begin(), refused_.end(), same)) {
    drop(index);
    return false;
  }
  const double kappa = radians(config_.kappa_deg);
  const std::vector<std::uint32_t> strict = scorer_.matching(accepted.plane);
  const bool level = std::abs(accepted.plane.normal.z()) >= std::cos(radians(45.0));
  if ((level && !liesOnPlane(accepted.plane, strict)) ||
      (spreadExceeds(grid_, directions_, strict, accepted.plane, config_.max_direction_spread_deg, patch_threads_) &&
       !(level && (nearlyLevel(accepted.plane) || noiseExplainsSpread(accepted.plane, strict))))) {
    refused_.push_back(accepted.plane);
    drop(index);
    return false;
  }
  const std::vector<std::uint32_t> matching =
      withEdges(grid_, directions_, scorer_, strict, accepted.plane, config_.epsilon, kappa);
  SplitPatches split = splitWithOutlineRuns(grid_, matching, accepted.plane.normal.cast<double>(),
                                            accepted.plane.point.cast<double>(), 2, patch_threads_);
  const std::size_t pieces = split.patches.size();
  const double cell_area = grid_.cellSize() * grid_.cellSize();
  joinUnseenGaps(grid_, split.patches, accepted.plane.normal.cast<double>(), accepted.plane.point.cast<double>(),
                 config_.epsilon, std::max<std::size_t>(config_.min_patch_blocks, 1), config_.min_patch_area / cell_area);
  // A join (a wall's pieces) leaves fewer patches: theirs are rasterised again for
  // their outlines.
  if (split.patches.size() != pieces) split.outline_runs.assign(split.patches.size(), {});
  const double min_width =
      (level ? config_.min_level_patch_width_cells : config_.min_patch_width_cells) * grid_.cellSize();
  std::vector<std::uint32_t> taken;
  for (std::size_t k = 0; k < split.patches.size(); ++k) {
    Patch& patch = split.patches[k];
    if (patch.surface * cell_area < config_.min_patch_area ||
        fitPoints(grid_, patch) < static_cast<std::size_t>(config_.min_patch_blocks) ||
        isThin(grid_, patch, accepted.plane, min_width, patch_threads_)) {
      continue;
    }
    if (taken.empty()) ++accepted_;
    // Described after the search (describePatches), its outline traced after the merges
    // (tracePendingOutlines) on the plane it was split on.
    Plane plane;
    undescribed_.push_back(Undescribed{accepted.plane, patch.surface});
    plane.id = static_cast<std::int32_t>(patches_.planes.size() + 1);
    plane.source = accepted_;
    plane.candidates = since_acceptance_;
    const auto patch_size = static_cast<std::int64_t>(patch.blocks.size());
#pragma omp parallel for schedule(static) num_threads(patch_threads_) if (patch_threads_ > 1 && patch_size > kParallelPatchBlocks)
    for (std::int64_t n = 0; n < patch_size; ++n) patches_.labels[patch.blocks[static_cast<std::size_t>(n)]] = plane.id;
    taken.insert(taken.end(), patch.blocks.begin(), patch.blocks.end());
    patches_.outline_runs.push_back(std::move(split.outline_runs[k]));
    patches_.blocks.push_back(std::move(patch.blocks));
    patches_.outline_frames.push_back(
        OutlineFrame{accepted.plane.normal.cast<double>(), accepted.plane.point.cast<double>(), true});
    patches_.planes.push_back(std::move(plane));
  }
  if (taken.empty()) {
    refused_.push_back(accepted.plane);
    drop(index);
    return false;
  }
  scorer_.take(taken);
  refused_.clear();
  std::vector<Candidate> remaining;
  for (Candidate& candidate : candidates_) {
    if (scorer_.taken(candidate.seeds[0]) || scorer_.taken(candidate.seeds[1]) || scorer_.taken(candidate.seeds[2])) {
      continue;
    }
    candidate.stale = true;
    remaining.push_back(std::move(candidate));
  }
  candidates_ = std::move(remaining);
  // Draws skip taken seeds; prune them once they are a quarter of the list.
  seedable_taken_ += taken.size();
  if (4 * seedable_taken_ > seedable_.size()) {
    std::erase_if(seedable_, [&](std::uint32_t id) { return scorer_.taken(id); });
    seedable_taken_ = 0;
  }
  since_acceptance_ = 0;
  return true;
}

PatchSet Detector::run(ErmsmStats& stats) {
  const auto start = Clock::now();
  stats_ = &stats;
  const int batch = std::max(1, config_.batch_size);
#ifdef _OPENMP
  const int threads = config_.threads > 0 ? config_.threads : omp_get_max_threads();
#endif
  // Batches are drawn on several threads while that beats one: a batch takes well under
  // a millisecond, and on a shared machine a parallel region can wait milliseconds for a
  // core (the 10 cm corridor's search took 0.5 s at 2 threads instead of 0.011 s, and
  // 0.02 s on one). Once a batch takes longer than its draws took added up, the rest are
  // drawn on one thread. The candidates are the same either way.
  bool parallel_draws = true;
  std::vector<double> draw_seconds(static_cast<std::size_t>(batch));
  std::uint64_t generated = 0;
  int empty_batches = 0;
  while (generated < static_cast<std::uint64_t>(config_.max_candidates) && seedable_.size() - seedable_taken_ >= 3) {
    std::vector<CandidateDraw> draws(static_cast<std::size_t>(batch));
    const CandidateSource candidate_source = source();
    const auto batch_start = Clock::now();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (parallel_draws)
    for (int k = 0; k < batch; ++k) {
      const auto draw_start = Clock::now();
      draws[static_cast<std::size_t>(k)] =
          drawCandidate(candidate_source, config_.seed, generated + static_cast<std::uint64_t>(k), candidates_);
      draw_seconds[static_cast<std::size_t>(k)] = secondsSince(draw_start);
    }
    if (parallel_draws) {
      double serial_seconds = 0.0;
      for (const double seconds : draw_seconds) serial_seconds += seconds;
      parallel_draws = secondsSince(batch_start) < serial_seconds;
    }
    generated += static_cast<std::uint64_t>(batch);
    bool any = false;
    for (CandidateDraw& drawn : draws) {
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
      if (acceptanceProbability(candidates_[*best]) < config_.min_probability) break;
      const auto accept_start = Clock::now();
      accept(*best);
      stats.stages.patches += secondsSince(accept_start);
      if (seedable_.size() - seedable_taken_ < 3) break;
    }
  }
  stats.accepted = static_cast<std::size_t>(accepted_);
  const auto describe_start = Clock::now();
  describePatches();
  stats.stages.patches += secondsSince(describe_start);
  stats.stages.search = std::max(0.0, secondsSince(start) - stats.stages.patches);
  const auto merge_start = Clock::now();
  // Block points sit at cell centres: pieces of one surface lie up to half a cell
  // further apart than ε allows a block.
  mergeCoplanar(grid_, patches_, config_.epsilon + 0.5 * grid_.cellSize(), radians(config_.kappa_deg));
  stats.stages.merges = secondsSince(merge_start);
  // Classification reads the outlines: the patches' and the merged groups' traced now.
  const auto outline_start = Clock::now();
  tracePendingOutlines(grid_, patches_, patchPassThreads(grid_, config_.threads));
  stats.stages.patches += secondsSince(outline_start);
  return std::move(patches_);
}

// Block heights average several points, so their scatter stays below the points':
// 3 σ. Real surfaces are not that flat over metres: on scans made elsewhere the
// points' RMS to their own plane reaches 2.1 cm (3DTK's floor), 2.6 cm (its ceiling),
// 2.3 cm (a wall of OctoMap's fr079): ε is at least min(cell, 5 cm), about two of
// those. Where blocks sit at cell centres (maps without point moments, format 2 and
// before), never less than a cell: a wall on a cell boundary has blocks half a cell
// either side of it.
double defaultEpsilon(bool at_points, double cell_size, double noise) {
  return at_points ? std::max(3.0 * noise, std::min(cell_size, 0.05))
                   : std::max(cell_size, std::min(3.0 * noise, 0.05));
}

// One detection with σ and ε resolved (config.noise, config.epsilon > 0).
// `block_noise`: the σ the blocks' variances were fused with (rangeNoise), which the rung
// test compares them in.
PlaneDetection detectOnce(MLMap& map, const ErmsmConfig& input_config, double block_noise) {
  const auto start = Clock::now();
  auto stage_start = start;
  PlaneDetection detection;
  ErmsmStats& stats = detection.stats;
  // Seconds since the last call: the stage that just ended.
  auto stage = [&stage_start] {
    const double seconds = secondsSince(stage_start);
    stage_start = Clock::now();
    return seconds;
  };
  ErmsmConfig& config = detection.config;
  config = input_config;
  // The blocks' old labels need no clearing: the write-back at the end labels every
  // map block (each lies in one eRMSM block), 0 where no patch took it.
  stats.stages.noise = stage();
  // A level rung is fused from a few points (under ten): its variance is a good part
  // of one point's σ², a table top's far below it; σ the build's, in which the blocks'
  // variances are, not the one measured on the planes.
  const BlockGrid grid(map, BlockGridConfig{.stack_gap = config.stack_gap,
                                            .level_band = 5.0 * config.noise,
                                            .ladder_gap = config.ladder_gap,
                                            .ladder_blocks = config.ladder_blocks,
                                            .rung_variance = 0.1 * block_noise * block_noise});
  stats.stages.grid = stage();
  DirectionConfig direction_config;
  direction_config.radius = config.radius;
  // Two directions off their plane's normal by s per axis differ by more than θ in one
  // pair of twenty when s = θ / (2.45 √2) (the difference's length is Rayleigh, 95 % below 2.45 √2 s).
  direction_config.max_radius = config.max_radius > 0 ? config.max_radius : 2 * config.radius;
  direction_config.max_tilt = radians(config.theta_deg) / (2.45 * std::sqrt(2.0));
  direction_config.height_tolerance = static_cast<float>(config.epsilon);
  direction_config.threads = config.threads;
  const DirectionField directions = directionField(grid, direction_config);
  stats.stages.directions = stage();
  stats.direction_seconds = secondsSince(start);
  stats.blocks = grid.size();
  stats.blocks_with_direction = static_cast<std::size_t>(
      std::count_if(directions.vectors.begin(), directions.vectors.end(), [](const Eigen::Vector3f& d) { return d.squaredNorm() > 0.0F; }));

  const auto detection_start = Clock::now();
  Detector detector(grid, directions, config);
  stats.stages.index = stage();
  PatchSet patches = detector.run(stats);
  stage();
  classifyPlanes(patches.planes);
  mergeLevels(grid, patches, radians(config.kappa_deg));
  tracePendingOutlines(grid, patches, patchPassThreads(grid, config.threads));  // the merged levels'
  stats.stages.merges += stage();
  detection.planes = std::move(patches.planes);
  // Each cell's blocks on their own: on all threads.
  const auto cells = static_cast<std::int64_t>(grid.cellCount());
  std::size_t labelled = 0;
#pragma omp parallel for schedule(static) num_threads(teamSize(patchPassThreads(grid, config.threads))) reduction(+ : labelled)
  for (std::int64_t n = 0; n < cells; ++n) {
    const auto cell = static_cast<std::size_t>(n);
    const auto blocks = map.mutableBlocksAt(grid.mapCellOf(cell));
    for (std::uint32_t id = grid.firstBlockOfCell(cell); id < grid.firstBlockOfCell(cell + 1); ++id) {
      const PlaneBlock& block = grid.blocks()[id];
      for (std::size_t k = block.map_first; k < block.map_first + block.map_count; ++k) {
        blocks[k].plane = patches.labels[id];
        if (blocks[k].plane != 0) ++labelled;
      }
    }
  }
  stats.labelled_blocks = labelled;
  stats.stages.labels = stage();
  // Everything after the direction vectors, the labels written back included.
  stats.detection_seconds = secondsSince(detection_start);
  return detection;
}

}  // namespace

// σ sets ε (3 σ), the level band (5 σ) and the rung variance. Without --noise it is the
// blocks' own variance first: what the build was told about its measurements (3 cm for
// points from a file, whatever the scanner), not what they are. Where the blocks keep
// their points, the planes of that first pass then measure it: the median RMS distance
// of a block's points from its patch (surface_noise.hpp), about the noise the planes
// must tolerate, surface waviness and registration included. On the real scans of
// bench/real_data.py at 5 cm cells, against 3 cm assumed: 3DTK 2.3 cm, OctoMap's fr079
// 0.9, Bobkov's room 1.9, PCL's office1 1.2 and room scans 1.2-1.3, plane_seg's stairs
// 1.0 and 0.8. The planes are detected again with it unless it lies within 25 % of the
// first σ: on those eight scans the estimate itself moves by 16-53 % (median 28 %)
// between 5 and 10 cm cells, and its median over 100 blocks spreads -11..-29 % to
// +15..+41 % (95 % of 400 bootstrap draws; surface_noise.hpp), so a smaller difference
// is not a measured one.
PlaneDetection detectPlanes(MLMap& map, const ErmsmConfig& input_config) {
  const auto start = Clock::now();
  const bool at_points = hasPointStats(map);
  const double block_noise = rangeNoise(map);
  ErmsmConfig config = input_config;
  const bool measure = config.noise <= 0.0 && at_points;
  if (config.noise <= 0.0) config.noise = block_noise;
  if (config.epsilon <= 0.0) config.epsilon = defaultEpsilon(at_points, map.cellSize(), config.noise);
  // Seconds before `detection`'s own (the estimates, a first pass) count as the noise stage.
  const auto chargeNoise = [](PlaneDetection& detection, double seconds) {
    detection.stats.stages.noise += seconds;
    detection.stats.direction_seconds += seconds;
  };
  const double estimate_seconds = secondsSince(start);
  PlaneDetection detection = detectOnce(map, config, block_noise);
  const std::optional<double> measured = measure ? surfaceNoise(map, detection.planes) : std::nullopt;
  if (!measured || *measured <= 0.0 || std::abs(std::log(*measured / config.noise)) <= std::log(1.25)) {
    chargeNoise(detection, estimate_seconds);
    return detection;
  }
  ErmsmConfig again = input_config;
  again.noise = *measured;
  // ε is widened by the measurement, never narrowed: a median over all blocks speaks for
  // the surfaces seen best, and a sparse, far one (3DTK's ceiling at 5 cm cells; the 4 cm
  // ceiling over a 1 cm floor of tests/test_planes_noisy.cpp) is lost with ε from the
  // floor's noise. Narrowing it found plane_seg's first stair tread at 5 cm cells and
  // lost room walls of PCL's room_scan1 and room_scan2.
  if (again.epsilon <= 0.0) again.epsilon = defaultEpsilon(at_points, map.cellSize(), std::max(config.noise, *measured));
  // σ sets only ε and the level band (never narrower than a cell): where neither moves
  // (a simulated scan's 0.4 cm against 1 cm assumed, both bands a cell), a second pass
  // would find the very same planes.
  const auto levelBand = [&map](double noise) { return std::max(5.0 * noise, map.cellSize()); };
  if (again.epsilon == config.epsilon && levelBand(again.noise) == levelBand(config.noise)) {
    detection.config.noise = again.noise;
    detection.stats.prior_noise = config.noise;
    chargeNoise(detection, estimate_seconds);
    return detection;
  }
  const double first_pass_seconds = secondsSince(start);
  detection = detectOnce(map, again, block_noise);
  detection.stats.prior_noise = config.noise;
  detection.stats.passes = 2;
  chargeNoise(detection, first_pass_seconds);
  return detection;
}

}  // namespace mlmap
