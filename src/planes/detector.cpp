#include "detector.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "direction_fit.hpp"
#include "fill_vector.hpp"
#include "mlmap/planes/classify.hpp"
#include "mlmap/planes/patches.hpp"
#include "outline_runs.hpp"
#include "patch_rules.hpp"
#include "seen_gaps.hpp"
#include "sheets.hpp"
#include "stepped.hpp"
#include "unseen_gaps.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap {
namespace {

// A patch of fewer blocks has its labels written on one thread.
constexpr std::int64_t kParallelPatchBlocks = 20000;


}  // namespace

int teamSize(int threads) {
#ifdef _OPENMP
  return threads > 0 ? threads : omp_get_max_threads();
#else
  (void)threads;
  return 1;
#endif
}

Detector::Detector(const BlockGrid& grid, const DirectionField& field, const ErmsmConfig& config, bool sheets)
    : grid_(grid),
      directions_(field.vectors),
      tilts_(field.tilts),
      config_(config),
      scorer_(grid, field.vectors, config.epsilon, radians(config.kappa_deg), config.threads),
      min_score_(config.min_area / (grid.cellSize() * grid.cellSize())),
      patch_threads_(teamSize(patchPassThreads(grid, config.threads))),
      sheet_step_(sheets ? sheetStep(config.noise, grid.cellSize()) : std::numeric_limits<double>::infinity()),
      fit_noise_(sheets ? config.noise : 0.0) {
  patches_.labels.assign(grid.size(), 0);
  FillVector<std::uint8_t> directed(grid.size());
  const auto blocks = static_cast<std::int64_t>(grid.size());
#pragma omp parallel for schedule(static) num_threads(patch_threads_) if (patch_threads_ > 1)
  for (std::int64_t id = 0; id < blocks; ++id) {
    directed[static_cast<std::size_t>(id)] = field.vectors[static_cast<std::size_t>(id)].squaredNorm() > 0.0F ? 1 : 0;
  }
  seedable_ = grid.idsInMapOrder(directed, patch_threads_);
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
// limit on top of that noise (the two adding in squares). Walls only where they are
// wall-sized (kWallSizedArea): a vertical block's direction is uncertain where its window
// holds a corner or a pillar's turn, which is what the spread rule is for (excusing
// every wall let 45° facets across the lab's corners and a 0.2 m cylinder's through).
bool Detector::noiseExplainsSpread(const CandidatePlane& plane, const std::vector<std::uint32_t>& strict) const {
  const double limit = spreadLimit(config_.max_direction_spread_deg, noiseSpread(tilts_, strict, radians(config_.kappa_deg)));
  return !spreadExceeds(grid_, directions_, strict, plane, limit, patch_threads_);
}

// A plumb plane is excused like a level one (noiseExplainsSpread) where its blocks cover
// at least this much, m²: a wall's worth, where a corner's or a pillar's facets, which the
// spread rule is for, cover a window or two. Dense walls with 3 cm of noise at 0.1 m cells
// spread 8.2-9.6° (make_scene.py's room turned 7°: three of four walls refused, 25-30 m²
// each). With 2 m² the simulated lab at 3 cm of noise and 5 cm cells also kept facets of
// 0.8-1.3 m² (planes_sweep.py noise2/noise3: F1 0.948 -> 0.947), with 4 m² none (0.949).
// Measured with 4 m² (session 45): make_scene.py's rooms at 2-3 cm of noise and 0.1 m,
// walls/floor/ceiling/table 0.883 -> 0.914 (seed 1), 0.909 -> 0.928 (seeds 2-3, not looked
// at); generated offices 5-8 (held out) with 2-3 cm of noise, F1 0.892 -> 0.901 at 0.05 m and
// 0.922 -> 0.924 at 0.1 m; the real scans of bench/real_seeds.py find the same surfaces
// (seeds 1-3), and 3DTK's curved upper-hall arches at 0.05 m (13.6 m², 8.6°) become two
// facets instead of a refusal. A curved wall with little noise stays refused (its spread is
// the curvature's, not the noise's): tests/test_planes_refused_walls.cpp.
constexpr double kWallSizedArea = 4.0;

double Detector::areaOf(const std::vector<std::uint32_t>& blocks) const {
  return surfaceOf(grid_, blocks) * grid_.cellSize() * grid_.cellSize();
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
  return medianDistance(grid_, strict, plane) <= scorer_.bandOf(plane) / 3.0;
}

// A plumb plane refused for its blocks' direction spread alone: kept in the stats where its
// blocks cover more than any refused before (a wall's worth tells the user, a corner's
// facet does not).
void Detector::noteRefusedWall(const CandidatePlane& plane, const std::vector<std::uint32_t>& strict) {
  if (stats_ == nullptr || !isPlumb(plane.normal.cast<double>())) return;
  const double area = areaOf(strict);
  if (area <= stats_->refused_wall_area) return;
  stats_->refused_wall_area = area;
  stats_->refused_wall_spread_deg = directionSpread(grid_, directions_, strict, plane);
}

void Detector::drop(std::size_t index) {
  unlisted_ += static_cast<std::size_t>(candidates_[index].multiplicity);
  candidates_.erase(candidates_.begin() + static_cast<long>(index));
}

// The patches of an accepted plane's blocks: its sheets (sheets.hpp), each cut into
// connected pieces (gap 2 cells) and a wall's pieces joined across unseen gaps; largest
// first. Neighbouring blocks of one sheet differ in their distance from the plane by at
// most sheet_step_; where that exceeds the slab (2 ε) every block is in one sheet and
// the pass is skipped.
SplitPatches Detector::splitSheets(const std::vector<std::uint32_t>& matching, const CandidatePlane& plane) const {
  const double step = sheet_step_;
  const double band = scorer_.bandOf(plane);
  const Eigen::Vector3d normal = plane.normal.cast<double>();
  const Eigen::Vector3d point = plane.point.cast<double>();
  SplitPatches split;
  if (step >= 2.0 * band) {
    split = splitWithOutlineRuns(grid_, matching, normal, point, 2, patch_threads_);
  } else {
    // Neighbours within 2 cells across, and in height within 2 cells or the stack gap
    // (blocks of a cell closer than it are one block), whichever is more: at 2 cm cells
    // blocks of one wall of the simulated lab lie further apart in height than 4 cm.
    const double max_rise = std::max(2.0 * grid_.cellSize(), config_.stack_gap);
    for (const std::vector<std::uint32_t>& sheet : sheetsOf(grid_, matching, plane, step, 2, max_rise)) {
      SplitPatches pieces = splitWithOutlineRuns(grid_, sheet, normal, point, 2, patch_threads_);
      for (std::size_t k = 0; k < pieces.patches.size(); ++k) {
        split.patches.push_back(std::move(pieces.patches[k]));
        split.outline_runs.push_back(std::move(pieces.outline_runs[k]));
      }
    }
    std::vector<std::size_t> order(split.patches.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return split.patches[a].surface > split.patches[b].surface; });
    SplitPatches sorted;
    for (const std::size_t k : order) {
      sorted.patches.push_back(std::move(split.patches[k]));
      sorted.outline_runs.push_back(std::move(split.outline_runs[k]));
    }
    split = std::move(sorted);
  }
  // Level pieces a gap apart that the scanner saw past are two surfaces.
  splitAtSeenGaps(grid_, split.patches, split.outline_runs, normal, point, band);
  // A wall's pieces are joined across unseen gaps along it, whichever sheet each came
  // from, where their mean distances from the plane lie within the step (one face).
  const std::size_t count = split.patches.size();
  joinUnseenGaps(grid_, split.patches, normal, point, band, std::max<std::size_t>(config_.min_patch_blocks, 1),
                 config_.min_patch_area / (grid_.cellSize() * grid_.cellSize()), 0.3, step);
  // A join leaves fewer patches: theirs are rasterised again for their outlines.
  if (split.patches.size() != count) split.outline_runs.assign(split.patches.size(), {});
  return split;
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
  // The tests an accepted plane must pass, on the blocks it matches.
  const auto refuses = [&](const CandidatePlane& plane, const std::vector<std::uint32_t>& blocks) {
    const bool level = std::abs(plane.normal.z()) >= std::cos(radians(45.0));
    if (level && !liesOnPlane(plane, blocks)) return true;
    if (!spreadExceeds(grid_, directions_, blocks, plane, config_.max_direction_spread_deg, patch_threads_)) return false;
    if (level ? nearlyLevel(plane) || noiseExplainsSpread(plane, blocks)
              : areaOf(blocks) >= kWallSizedArea && noiseExplainsSpread(plane, blocks)) {
      return false;
    }
    // A flight seen from above (treads and risers; stepped.hpp cuts it after the search)
    // spreads its blocks' directions by design: it is not refused for that.
    return !isFlightFromAbove(grid_, blocks, plane.normal.cast<double>().normalized(), plane.point.cast<double>(),
                              StepConfig{config_.noise, config_.min_patch_blocks, config_.min_patch_area});
  };
  // The plane the patches are cut from: the candidate's, or turned onto its blocks'
  // directions where its fit leans between two layers (direction_fit.hpp) and the tests
  // pass the turned one (on 3DTK's hall at 5 cm cells they refused some, and refusing the
  // candidate with them cost patches and a third of the search's time).
  CandidatePlane cut = accepted.plane;
  std::vector<std::uint32_t> strict = scorer_.matching(cut);
  const double plumb_tilt = radians(ClassifyConfig{}.horizontal_deg);  // the walls' class, as the sparse growth's
  const std::optional<CandidatePlane> turned = alongDirections(grid_, directions_, scorer_, strict, cut, plumb_tilt);
  std::vector<std::uint32_t> turned_strict = turned ? scorer_.matching(*turned) : std::vector<std::uint32_t>{};
  if (turned && !refuses(*turned, turned_strict)) {
    cut = *turned;
    strict = std::move(turned_strict);
  } else if (refuses(cut, strict)) {
    noteRefusedWall(cut, strict);
    refused_.push_back(accepted.plane);
    drop(index);
    return false;
  }
  const bool level = std::abs(cut.normal.z()) >= std::cos(radians(45.0));
  const std::vector<std::uint32_t> matching =
      withEdges(grid_, directions_, scorer_, strict, cut, scorer_.bandOf(cut), kappa);
  const double cell_area = grid_.cellSize() * grid_.cellSize();
  // A staircase's ramp (stepped.hpp) stays one patch across a step's going, so that its
  // steps are cut from it after the search (splitSteps): split two cells apart, as other
  // planes are, a flight seen from below at 5 cm cells came apart into its bands and the
  // bands into their pieces between the balusters' shadows, pieces under a patch's size
  // were dropped and the others kept the ramp's plane (fr079: 2 of its 13 steps found).
  const Eigen::Vector3d cut_normal = cut.normal.cast<double>().normalized();
  SplitPatches split;
  if (isStaircaseRamp(grid_, matching, cut_normal, config_.noise)) {
    const int going_cells = std::max(2, static_cast<int>(std::ceil(kStepGoing / grid_.cellSize() - 1e-9)));
    split = splitWithOutlineRuns(grid_, matching, cut_normal, cut.point.cast<double>(), going_cells, patch_threads_);
  } else {
    split = splitSheets(matching, cut);
  }
  const double min_width =
      (level ? config_.min_level_patch_width_cells : config_.min_patch_width_cells) * grid_.cellSize();
  std::vector<std::uint32_t> taken;
  for (std::size_t k = 0; k < split.patches.size(); ++k) {
    Patch& patch = split.patches[k];
    if (patch.surface * cell_area < config_.min_patch_area ||
        fitPoints(grid_, patch) < static_cast<std::size_t>(config_.min_patch_blocks) ||
        isThin(grid_, patch, cut, min_width, patch_threads_)) {
      continue;
    }
    if (taken.empty()) ++accepted_;
    // Described after the search (describePatches), its outline traced after the merges
    // (tracePendingOutlines) on the plane it was split on.
    Plane plane;
    undescribed_.push_back(Undescribed{cut, patch.surface});
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
        OutlineFrame{cut.normal.cast<double>(), cut.point.cast<double>(), true});
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
  const auto growth_start = Clock::now();
  growIntoSparse(0);
  // The sparse surfaces found next grow the same way: into the blocks of their surface
  // that have a direction (a noisy wall's, off by its noise, which no candidate matched).
  const std::size_t before_sparse = patches_.planes.size();
  findSparse();
  growIntoSparse(before_sparse);
  stats.stages.patches += secondsSince(growth_start);
  const auto describe_start = Clock::now();
  describePatches();
  stats.stages.patches += secondsSince(describe_start);
  stats.stages.search = std::max(0.0, secondsSince(start) - stats.stages.patches);
  const auto merge_start = Clock::now();
  // Block points sit at cell centres (before format 3): pieces of one surface lie up to
  // half a cell further apart than ε allows a block. Where they sit at their points, a
  // piece further off than a sheet's step is another layer (sheets.hpp).
  mergeCoplanar(grid_, patches_, std::min(config_.epsilon + 0.5 * grid_.cellSize(), sheet_step_),
                radians(config_.kappa_deg), fit_noise_);
  stats.stages.merges = secondsSince(merge_start);
  // Classification reads the outlines: the patches' and the merged groups' traced now.
  const auto outline_start = Clock::now();
  tracePendingOutlines(grid_, patches_, patchPassThreads(grid_, config_.threads));
  stats.stages.patches += secondsSince(outline_start);
  return std::move(patches_);
}

}  // namespace mlmap
