// Internal to eRMSM: Algorithm 1 of section V over one map's blocks. Candidates in
// batches, the best one accepted while eq. 10 says a better one is unlikely to have been
// overlooked; then, beyond the paper, each accepted plane cut into sheets and connected
// patches, and patches of one surface merged. The steps live in their own files:
// direction_vectors (Fig. 4), candidates (newCandidates, Fig. 5c, Algorithm 2),
// plane_scorer (the score in surface units), patch_rules, sheets, patches and
// unseen_gaps (what an accepted plane keeps), patch_set (merges).
#pragma once

#include <chrono>
#include <cstdint>
#include <numbers>
#include <optional>
#include <vector>

#include "candidates.hpp"
#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/direction_vectors.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "outline_runs.hpp"
#include "patch_merges.hpp"
#include "patch_set.hpp"
#include "plane_scorer.hpp"
#include "sparse_growth.hpp"
#include "sparse_search.hpp"

namespace mlmap {

using Clock = std::chrono::steady_clock;

inline double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

inline double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// Threads for the passes over the kept patches (descriptions, outlines): maps under
// 100 000 blocks use one, as the scorer's index does. There the passes take a few
// milliseconds, and on a shared machine a parallel region can wait as long for a core.
inline int patchPassThreads(const BlockGrid& grid, int threads) { return grid.size() < 100000 ? 1 : threads; }

// The threads an OpenMP region of `threads` (0: OpenMP's default) gets.
int teamSize(int threads);

class Detector {
 public:
  // `sheets`: cut planes into sheets (the blocks keep their points' moments, σ is known).
  Detector(const BlockGrid& grid, const DirectionField& field, const ErmsmConfig& config, bool sheets);

  // Algorithm 1; the patches it leaves, coplanar pieces merged.
  PatchSet run(ErmsmStats& stats);

 private:
  CandidateSource source() const {
    return CandidateSource{grid_, directions_, scorer_, seedable_, config_.radius,
                           static_cast<float>(std::cos(radians(config_.theta_deg))), config_.max_refits,
                           config_.refit_gain, static_cast<float>(config_.max_epsilon)};
  }
  std::optional<std::size_t> bestCandidate();
  double acceptanceProbability(const Candidate& leader) const;
  bool noiseExplainsSpread(const CandidatePlane& plane, const std::vector<std::uint32_t>& strict) const;
  bool nearlyLevel(const CandidatePlane& plane) const;
  double areaOf(const std::vector<std::uint32_t>& blocks) const;  // m², of the blocks' surface
  bool liesOnPlane(const CandidatePlane& plane, const std::vector<std::uint32_t>& strict) const;
  void noteRefusedWall(const CandidatePlane& plane, const std::vector<std::uint32_t>& strict);
  SplitPatches splitSheets(const std::vector<std::uint32_t>& matching, const CandidatePlane& plane) const;
  bool accept(std::size_t index);
  void drop(std::size_t index);

  const BlockGrid& grid_;
  const std::vector<Eigen::Vector3f>& directions_;
  const std::vector<float>& tilts_;
  const ErmsmConfig& config_;
  PlaneScorer scorer_;
  double min_score_;
  int patch_threads_;  // for the passes over an accepted plane's blocks
  // m: neighbouring blocks of one sheet differ by at most this in their distance from
  // their plane (splitSheets, sheetStep); infinite without sheets, as for blocks at cell
  // centres (maps before format 3), where a wall on a cell boundary is two columns a cell
  // apart.
  double sheet_step_;
  // m: σ for the patches' fits (describePatch), where it is known (given, or measured
  // by a first pass); 0 on a pass that measures it.
  double fit_noise_;
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
  void growIntoSparse(std::size_t first);
  void findSparse();
};

}  // namespace mlmap
