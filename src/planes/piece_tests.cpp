// Whether the smaller of two pieces may be part of the larger's surface (piece_tests.hpp).
#include "piece_tests.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "median.hpp"

namespace mlmap {
namespace {

// A surface's points beyond a cell boundary a distance u from it (the next cell column
// out) make blocks of their own, and where their mean lies beyond ε (2 cm cells, or walls
// seen head on with more range noise than the map's σ, read mostly on grazing floors) those
// are accepted as a plane of their own, parallel to the surface: a noise tail. The part of a
// normal spread σ beyond u = k σ has its mean 0.28-0.52 σ beyond u, and beyond 3 σ a column
// holds almost none of the points. So a parallel piece within kTailSigmas of the larger's RMS
// of its plane may be the larger's tail, and the joint fit decides (mergeCoplanar's sheet
// test: a real layer in front of a surface, a board or a door frame, moves the joint plane's
// RMS beyond the surfaces' own spread). Measured (bench/planes_sweep.py, held-out offices,
// lab and corridor, turned 0, 2 and 15 deg): the aligned 2 cm variants F1 0.74-0.91 ->
// 0.79-0.95 (the lab's walls on cell boundaries came with planes 2.3-2.6 cm either side, 0.3
// cm RMS against 0.8 cm), 2 cm range noise at 5 cm cells 0.78-0.83 -> 0.81-0.86, no variant
// worse; PCL's office1 at 5 cm cells (a depth camera's far wall in layers) three patches ->
// one. A first version also asked the piece's RMS to be at most half the larger's (a clean
// tail's); a wall turned 10 deg with 3 cm of range noise left tails 6-8 cm off it with 0.6-0.8
// of its RMS, planes of their own 2 deg off it through its staircase's cell columns (the
// simulated lab: four; tests/test_planes_turned.cpp): without it the default sweep's F1
// 0.9348 -> 0.9368, offices 13-16 and halls 3-4 with 1-3 cm noise 0.8851 -> 0.8858, no variant
// worse, the real scans' patches the same.
constexpr double kTailSigmas = 3.5;

// A tail can lie further out than kTailSigmas of the larger's RMS: that RMS is of the
// points its patch took, which end about ε from its plane, and it reads the noise low.
// The simulated lab turned 10° with 3 cm of range noise (σ read 1.4 cm, ε 6.1 cm): its
// walls' patches have 2.0-2.4 cm RMS, and the tails beside them, 6.6-11.3 cm off (up to 5.1
// RMS), were a phantom wall in 4 of 8 search seeds (tests/test_planes_turned.cpp). What
// tells such a tail from a board or a door frame in front of the surface is how few points
// it holds: beyond 2 σ lie 2 % of a surface's points, while a real face beside it, seen
// from the same place, is sampled like the surface. So a piece that far whose blocks hold
// under kTailDensity of the points per unit of surface of the larger's blocks next to it
// is a tail candidate too, and the joint fit decides as for the others. The constants from
// the noise: those walls' RMS reads 0.67-0.8 of the 3 cm, so a tail's 3.5 σ reaches 5.2 of
// it (kSparseTailSigmas 5.5); a tail's blocks hold 3-5 % of the wall's points (11-20 against
// ~400), a quarter keeps a face sampled even at half its surface's density. No real scan of
// bench/real_data.py, no room of bench/peer_scene.py and no stair of bench/stairs_bench.py
// changed with it; bench/planes_sweep.py F1 0.9478 -> 0.9483, no variant worse.
constexpr double kSparseTailSigmas = 5.5;
constexpr double kTailDensity = 0.25;

// Points per unit of surface (PlaneBlock::surface) of the blocks `ids`.
double pointsPerSurface(const BlockGrid& grid, const std::vector<std::uint32_t>& ids) {
  double points = 0.0;
  for (const std::uint32_t id : ids) points += grid.pointsOf(id).count;
  const double surface = surfaceOf(grid, ids);
  return surface > 0.0 ? points / surface : 0.0;
}

}  // namespace

bool isNoiseTail(const Plane& larger, double apart) { return larger.rms > 0.0 && apart < kTailSigmas * larger.rms; }

bool isSparseTail(const BlockGrid& grid, const PatchSet& set, std::size_t smaller, const Plane& larger, double apart,
                  int radius) {
  if (larger.rms <= 0.0 || apart >= kSparseTailSigmas * larger.rms) return false;
  std::vector<std::uint32_t> beside;
  for (const std::uint32_t id : set.blocks[smaller]) {
    grid.forEachNeighbour(grid.blocks()[id].cell, radius, [&](std::uint32_t other) {
      if (set.labels[other] == larger.id) beside.push_back(other);
    });
  }
  if (beside.empty()) return false;
  std::sort(beside.begin(), beside.end());
  beside.erase(std::unique(beside.begin(), beside.end()), beside.end());
  const double own = pointsPerSurface(grid, set.blocks[smaller]);
  return own < kTailDensity * pointsPerSurface(grid, beside);
}

double seamApart(const BlockGrid& grid, const PatchSet& set, std::size_t smaller, const Plane& larger, int radius) {
  std::vector<float> distances;
  for (const std::uint32_t id : set.blocks[smaller]) {
    bool near = false;
    grid.forEachNeighbour(grid.blocks()[id].cell, radius, [&](std::uint32_t other) {
      near = near || set.labels[other] == larger.id;
    });
    if (!near) continue;
    const Eigen::Vector3d point = grid.blocks()[id].point.cast<double>();
    distances.push_back(static_cast<float>(std::abs(larger.normal.dot(point) + larger.offset)));
  }
  return distances.empty() ? std::numeric_limits<double>::infinity() : medianOf(distances);
}

double oneSurfaceRms(double noise, double own) {
  return std::hypot(own, 1.5 * std::numbers::sqrt2 * std::max(noise, own));
}

bool withinSheet(const PointMoments& piece, const Plane& larger, const Eigen::Vector3d& origin, double noise,
                 double width) {
  if (piece.count < 3.0) return false;
  // Narrow: the spread across its length (the middle axis of its points) within `width`.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(piece.covariance(), Eigen::EigenvaluesOnly);
  if (std::sqrt(std::max(0.0, solver.eigenvalues()(1))) > width) return false;
  const double offset = larger.offset + larger.normal.dot(origin);
  const double mean_square = larger.normal.dot(piece.outer * larger.normal) / piece.count +
                             2.0 * offset * larger.normal.dot(piece.mean()) + offset * offset;
  return std::sqrt(std::max(0.0, mean_square)) <= oneSurfaceRms(noise, larger.rms);
}

}  // namespace mlmap
