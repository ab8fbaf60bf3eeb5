// Internal to eRMSM: candidate planes (section V). newCandidates of Algorithm 1 draws
// a random block and two more within radius r whose direction vectors agree within θ;
// the plane goes through their barycentre with the mean of their directions as its
// normal (Fig. 5c). Algorithm 2 then refits it by PCA over its matching blocks.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "plane_scorer.hpp"

namespace mlmap {

struct Candidate {
  CandidatePlane plane;
  PlaneScore score;
  std::array<std::uint32_t, 3> seeds{};
  int multiplicity = 1;  // candidates drawn that re-found this one
  bool stale = false;    // blocks were taken since it was scored
};

struct CandidateDraw {
  std::optional<Candidate> candidate;  // scored and refitted
  int duplicate_of = -1;               // index of a listed candidate whose plane all three seeds match
};

struct CandidateSource {
  const BlockGrid& grid;
  const std::vector<Eigen::Vector3f>& directions;
  const PlaneScorer& scorer;
  const std::vector<std::uint32_t>& seedable;  // blocks the first seed is drawn from (some may be taken)
  int radius = 2;                               // cells, r
  float cos_theta = 1.0F;                       // of θ
  int max_refits = 5;                           // Algorithm 2's iterations at most
  double refit_gain = 1.0;                      // surface units
  float max_epsilon = 0.0F;                     // m, the widest ε a candidate may widen to (0: the scorer's)
};

// Candidate number `number` of a run seeded with `seed`: its own generator, so the
// same candidates come out at any thread count. A candidate whose three seeds all
// match a listed candidate's plane re-finds it and is not scored again.
CandidateDraw drawCandidate(const CandidateSource& source, std::uint64_t seed, std::uint64_t number,
                            const std::vector<Candidate>& listed);

// Algorithm 2: scores the candidate, then refits its normal (and point) by PCA over
// its matching blocks until the score gains less than the threshold; a refit that
// loses is undone. Beyond the paper, a candidate whose blocks spread so widely about it
// that its band cuts their noise widens its ε (up to source.max_epsilon) and is refitted
// again.
void refitCandidate(const CandidateSource& source, Candidate& candidate);

}  // namespace mlmap
