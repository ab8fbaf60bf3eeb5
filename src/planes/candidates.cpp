#include "candidates.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <random>

#include "mlmap/planes/direction_vectors.hpp"

namespace mlmap {
namespace {

std::uint64_t candidateSeed(std::uint64_t seed, std::uint64_t number) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * (number + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

}  // namespace

CandidateDraw drawCandidate(const CandidateSource& source, std::uint64_t seed, std::uint64_t number,
                            const std::vector<Candidate>& listed) {
  CandidateDraw result;
  if (source.seedable.empty()) return result;
  std::mt19937_64 random(candidateSeed(seed, number));
  constexpr int kAttempts = 8;
  std::vector<std::uint32_t> neighbours;
  const auto& directions = source.directions;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    const std::uint32_t first =
        source.seedable[std::uniform_int_distribution<std::size_t>(0, source.seedable.size() - 1)(random)];
    if (source.scorer.taken(first)) continue;
    const Eigen::Vector3f& first_direction = directions[first];
    neighbours.clear();
    source.grid.forEachNeighbour(source.grid.blocks()[first].cell, source.radius, [&](std::uint32_t id) {
      if (id != first && !source.scorer.taken(id) && std::abs(directions[id].dot(first_direction)) >= source.cos_theta) {
        neighbours.push_back(id);
      }
    });
    if (neighbours.size() < 2) continue;
    std::uniform_int_distribution<std::size_t> pick(0, neighbours.size() - 1);
    const std::size_t second_index = pick(random);
    std::size_t third_index = pick(random);
    if (third_index == second_index) third_index = (second_index + 1) % neighbours.size();
    const std::uint32_t second = neighbours[second_index];
    const std::uint32_t third = neighbours[third_index];
    if (std::abs(directions[second].dot(directions[third])) < source.cos_theta) continue;
    Candidate candidate;
    candidate.seeds = {first, second, third};
    Eigen::Vector3f normal = Eigen::Vector3f::Zero();
    Eigen::Vector3f point = Eigen::Vector3f::Zero();
    for (const std::uint32_t id : candidate.seeds) {
      const Eigen::Vector3f& direction = directions[id];
      normal += direction.dot(first_direction) < 0.0F ? Eigen::Vector3f(-direction) : direction;
      point += source.grid.blocks()[id].point;
    }
    candidate.plane.normal = orientConsistently(normal);
    candidate.plane.point = point / 3.0F;
    for (std::size_t k = 0; k < listed.size(); ++k) {
      const CandidatePlane& plane = listed[k].plane;
      if (source.scorer.matches(first, plane) && source.scorer.matches(second, plane) &&
          source.scorer.matches(third, plane)) {
        result.duplicate_of = static_cast<int>(k);
        return result;
      }
    }
    refitCandidate(source, candidate);
    result.candidate = candidate;
    return result;
  }
  return result;
}

namespace {

// Algorithm 2's loop on a scored candidate.
void refitScored(const CandidateSource& source, Candidate& candidate) {
  for (int iteration = 0; iteration < source.max_refits; ++iteration) {
    const PlaneScore& score = candidate.score;
    if (score.pca.weight < 3.0) return;
    const Eigen::Vector3d mean = score.pca.mean();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(score.pca.covariance());
    Eigen::Vector3f normal = solver.eigenvectors().col(0).cast<float>();
    if (!(normal.squaredNorm() > 0.5F)) return;
    if (normal.dot(candidate.plane.normal) < 0.0F) normal = -normal;
    const CandidatePlane refitted{orientConsistently(normal), candidate.plane.point + mean.cast<float>(),
                                  candidate.plane.epsilon};
    PlaneScore refitted_score = source.scorer.score(refitted);
    const double gain = refitted_score.score - score.score;
    if (gain < 0.0) return;
    candidate.plane = refitted;
    candidate.score = std::move(refitted_score);
    if (gain < source.refit_gain) return;
  }
}

// The most the blocks a band holds may spread about its plane (RMS) for a fraction of
// its half-width ε: blocks of a surface whose noise the band holds spread by σ_b ≤ ε / 3,
// an RMS of 0.33 ε; a band of ±2.3 σ_b cuts 2 % of a normal spread and leaves 0.40 ε
// (±1 σ_b 0.54 ε, blocks spread evenly over the band 0.58 ε). With 0.45 ε (a band of
// ±2 σ_b), a level plane through tests/test_planes_noisy.cpp's heap of clutter kept
// ε from the floor's noise (its blocks' means lie 2.2 cm RMS about it) and was a patch.
constexpr double kMaxSpreadInBand = 0.4;

// Whether the band ±ε cuts the spread of the blocks it holds: their RMS distance from
// the plane beyond kMaxSpreadInBand ε.
bool bandCutsSpread(const CandidatePlane& plane, const PlaneScore& score, float band) {
  if (score.pca.weight < 3.0) return false;
  const Eigen::Vector3d normal = plane.normal.cast<double>();
  const Eigen::Vector3d mean = score.pca.mean();
  // About the plane, not the blocks' mean: the spread the band holds.
  const double offset = normal.dot(mean);
  const double variance = normal.dot(score.pca.covariance() * normal) + offset * offset;
  return std::sqrt(std::max(0.0, variance)) > kMaxSpreadInBand * band;
}

}  // namespace

void refitCandidate(const CandidateSource& source, Candidate& candidate) {
  candidate.score = source.scorer.score(candidate.plane);
  refitScored(source, candidate);
  // Widened in steps of 1.5: a band of ±1 σ_b widens to ±2.25 σ_b in two.
  for (float band = source.scorer.bandOf(candidate.plane); band < source.max_epsilon;
       band = source.scorer.bandOf(candidate.plane)) {
    if (!bandCutsSpread(candidate.plane, candidate.score, band)) break;
    candidate.plane.epsilon = std::min(1.5F * band, source.max_epsilon);
    candidate.score = source.scorer.score(candidate.plane);
    refitScored(source, candidate);
  }
}

}  // namespace mlmap
