#include "stepped.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include "mlmap/planes/classify.hpp"

namespace mlmap {
namespace {

// Fewer points than this (beyond one per block) measure no spread: the patch stays.
constexpr double kMinDof = 10.0;
// A step seen from below is its riser and the nosing above it, and the lower steps, seen
// more steeply, show a strip of their treads too: a step's band is an edge, its points
// spread along its own plane by more than the noise (fr079's bands: 1.0-2.4 cm against
// 0.8-1.4 cm of noise). It is kept within the slab the search allows a block about a
// plane, ε = 3 σ (ErmsmConfig::epsilon); measured on fr079 alone, the one scan of
// ../shared/data with a staircase seen from below.
constexpr double kMaxStepSpreadOverNoise = 3.0;

// m: the bins along the fall line are half of this (or of a cell, where finer). There each
// block counts as its points lie, a normal density at their mean with their own spread
// along the line (and a bin's), not as a count in its mean's bin smoothed over a cell: at
// 10 cm cells that smoothing filled the 5-20 cm gaps between fr079's bands, and the cut left
// two or three bands in one step. bench/real_seeds.py --only fr079, seeds 1-3, its 20
// marked surfaces found at 5 / 10 cm cells (of 60): counted in a cell's bins 31 / 33;
// by their spread with this at 0.1 m 33 / 37, 0.05 m 33 / 38, 0.04 m 33 / 42, 0.03 m
// 32 / 44, 0.02 m 30 / 48. Counted in bins of 2.5 cm instead, the treads of a flight seen
// from above at 10 cm cells (blocks 10 cm apart in their cells' centres) came apart at every
// cell (tests/test_planes_stairs_below.cpp).
constexpr double kBandWindow = 0.03;

bool isStepped(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
               double noise) {
  const BlockSpread spread = spreadAlong(grid, blocks, normal);
  return spread.dof >= kMinDof && spread.rms > kOneSurfaceSpread * noise;
}

// The points' mean of block `id` (its cell centre and h where it keeps no points).
Eigen::Vector3d meanOf(const BlockGrid& grid, std::uint32_t id) {
  const PointStats stats = grid.pointsOf(id);
  return stats.empty() ? Eigen::Vector3d(grid.blocks()[id].point.cast<double>())
                       : Eigen::Vector3d(grid.pointsFrameOf(id) + stats.mean());
}

// Where the ramp's blocks lie along its fall line: their points' mean, m, and their
// points as weight.
struct Sample {
  double along = 0.0;
  double weight = 0.0;
  std::uint32_t id = 0;
  double variance = 0.0;  // m², of its points along the axis
};

// The ramp's blocks in steps: cut along `axis` (unit: the fall line, or up) at the valleys
// between the steps. The blocks' points, binned every half `window` along it and smoothed
// over a window (`spread`: each block a normal density of its points' spread along the
// axis), peak once per step (along the fall line a riser's points share its position; up
// the flight a tread's share its height); two peaks are two steps where the least between
// them is at most half the lower one, or two empty bins. Each step's ids ascending.
std::vector<std::vector<std::uint32_t>> stepsOf(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                                const Eigen::Vector3d& axis, double window, bool spread = false) {
  std::vector<Sample> samples;
  samples.reserve(blocks.size());
  for (const std::uint32_t id : blocks) {
    const PointStats stats = grid.pointsOf(id);
    const double points = stats.count;
    const double variance = spread && stats.count > 1 ? axis.dot(stats.scatterMatrix() * axis) / points : 0.0;
    samples.push_back({meanOf(grid, id).dot(axis), std::max(1.0, points), id, variance});
  }
  std::sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.along < b.along; });
  const double bin = window / 2.0;
  const double low = samples.front().along;
  const double span = (samples.back().along - low) / bin;
  // A flight of stairs spans metres; a patch a bin per block's width further (or no
  // finite span at all) is no staircase to cut: one step.
  std::vector<std::vector<std::uint32_t>> whole(1, blocks);
  if (!(span < 4.0 * static_cast<double>(samples.size()) + 16.0)) return whole;
  const auto bins = static_cast<std::size_t>(span) + 1;
  std::vector<double> density(bins, 0.0);
  if (spread) {
    // Each block's points spread normally about their mean (and within a bin).
    for (const Sample& sample : samples) {
      const double sigma = std::sqrt(sample.variance + bin * bin);
      const double centre = (sample.along - low) / bin;
      const auto from = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::floor(centre - 3.0 * sigma / bin)));
      const auto to = std::min(static_cast<std::int64_t>(bins) - 1,
                               static_cast<std::int64_t>(std::ceil(centre + 3.0 * sigma / bin)));
      for (std::int64_t b = from; b <= to; ++b) {
        const double z = (static_cast<double>(b) + 0.5 - centre) * bin / sigma;
        density[static_cast<std::size_t>(b)] += sample.weight * std::exp(-0.5 * z * z) * bin / sigma;
      }
    }
  } else {
    std::vector<double> weight(bins, 0.0);
    for (const Sample& sample : samples) weight[static_cast<std::size_t>((sample.along - low) / bin)] += sample.weight;
    const auto empty = [&](std::size_t b) { return b >= bins || weight[b] == 0.0; };
    for (std::size_t b = 0; b < bins; ++b) {
      // Two empty bins in a row stay empty: smoothed, such a gap between two steps would be
      // no valley (treads a riser apart, 3.5 bins, seen from above). A single empty bin is
      // the spacing of the blocks' cells (half a cell: the fall line's bins).
      if (empty(b) && ((b > 0 && empty(b - 1)) || empty(b + 1))) continue;
      density[b] = 2.0 * weight[b] + (b > 0 ? weight[b - 1] : 0.0) + (b + 1 < bins ? weight[b + 1] : 0.0);
    }
  }
  // A valley between two steps: the density falls to at most half the step's peak and
  // climbs back to twice the valley's (empty bins between two steps always cut).
  std::vector<std::size_t> cuts;  // bins where a new step begins
  std::size_t peak = 0;           // the highest bin of the current step
  std::size_t valley = 0;         // the lowest bin since that peak
  for (std::size_t b = 1; b < bins; ++b) {
    if (valley == peak && density[b] >= density[peak]) {
      peak = valley = b;  // still climbing
    } else if (density[b] < density[valley]) {
      valley = b;
    } else if (density[b] > 2.0 * density[valley] && density[peak] >= 2.0 * density[valley]) {
      cuts.push_back(valley);
      peak = valley = b;
    } else if (density[b] > density[peak]) {
      peak = valley = b;  // a shallow dip: the same step, climbing higher
    }
  }
  std::vector<std::vector<std::uint32_t>> steps(cuts.size() + 1);
  std::size_t step = 0;
  for (const Sample& sample : samples) {
    const auto b = static_cast<std::size_t>((sample.along - low) / bin);
    while (step < cuts.size() && b >= cuts[step]) ++step;
    steps[step].push_back(sample.id);
  }
  for (std::vector<std::uint32_t>& ids : steps) std::sort(ids.begin(), ids.end());
  return steps;
}

// A step's band reaches further than the ramp did (at 5 cm cells fr079's ramps were pieces
// of the flight's width): it takes the blocks of no patch that touch it (cells within
// `reach`), lie within `band` of its plane and within its own stretch of the fall line
// (`fall`, and half a cell either side: not the next step's). Returns whether it took
// any; `blocks` stays ascending.
bool growStep(const BlockGrid& grid, std::vector<std::int32_t>& labels, std::vector<std::uint32_t>& blocks,
              const Plane& plane, const Eigen::Vector3d& fall, int reach, double band) {
  double first = std::numeric_limits<double>::infinity();
  double last = -first;
  for (const std::uint32_t id : blocks) {
    const double along = meanOf(grid, id).dot(fall);
    first = std::min(first, along);
    last = std::max(last, along);
  }
  first -= 0.5 * grid.cellSize();
  last += 0.5 * grid.cellSize();
  const std::size_t before = blocks.size();
  for (std::size_t n = 0; n < blocks.size(); ++n) {
    grid.forEachNeighbour(grid.blocks()[blocks[n]].cell, reach, [&](std::uint32_t other) {
      if (labels[other] != 0) return;
      const Eigen::Vector3d mean = meanOf(grid, other);
      const double along = mean.dot(fall);
      if (along < first || along > last || std::abs(plane.normal.dot(mean) + plane.offset) > band) return;
      labels[other] = plane.id;
      blocks.push_back(other);
    });
  }
  std::sort(blocks.begin(), blocks.end());
  return blocks.size() > before;
}

// Whether block `id` may be a tread's: three points or more, spread up (along z) by at most
// 2 σ (a riser's or a wall's piece spreads up it; one or two points tell nothing).
bool levelBlock(const BlockGrid& grid, std::uint32_t id, double noise) {
  const BlockSpread spread = spreadAlong(grid, {id}, Eigen::Vector3d::UnitZ());
  return spread.dof >= 2.0 && spread.rms <= kOneSurfaceSpread * noise;
}

// The steps of `segments` that keep a patch: as large as a patch must be and, on their own
// plane, within 3 σ.
struct KeptSteps {
  std::vector<Patch> patches;
  std::vector<Plane> planes;
};
KeptSteps keptSteps(const BlockGrid& grid, std::vector<std::vector<std::uint32_t>> segments,
                    const CandidatePlane& reference, const StepConfig& config) {
  const double cell_area = grid.cellSize() * grid.cellSize();
  KeptSteps kept;
  for (std::vector<std::uint32_t>& ids : segments) {
    Patch step;
    step.surface = surfaceOf(grid, ids);
    step.blocks = std::move(ids);
    if (step.blocks.size() < static_cast<std::size_t>(config.min_blocks) || step.surface * cell_area < config.min_area)
      continue;
    // Its own plane, turned as far as the points say (a riser seen from below leans far
    // from the ramp): the reference only orients the normal. Fitted to all of its blocks'
    // points (noise 0): a band seen from below is its riser and its nosing both, and
    // describePatch's σ rule (blocks whose mean lies 3 σ off left out) took nosing blocks
    // out of fr079's bands (real_data.py: RMS within 0.5 cm of the points' own fit 47 -> 48
    // of 64 at 5 cm with all of them).
    Plane described = describePatch(grid, step, reference, std::numbers::pi / 2, 0.0);
    if (spreadAlong(grid, step.blocks, described.normal.normalized()).rms > kMaxStepSpreadOverNoise * config.noise)
      continue;
    kept.patches.push_back(std::move(step));
    kept.planes.push_back(std::move(described));
  }
  return kept;
}

}  // namespace

BlockSpread spreadAlong(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal) {
  double scatter = 0.0;
  BlockSpread spread;
  for (const std::uint32_t id : blocks) {
    const PointStats stats = grid.pointsOf(id);
    if (stats.count < 2) continue;
    scatter += normal.dot(stats.scatterMatrix() * normal);
    spread.dof += stats.count - 1.0;
  }
  if (spread.dof > 0.0) spread.rms = std::sqrt(std::max(0.0, scatter / spread.dof));
  return spread;
}

bool isStaircaseRamp(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
                     double noise) {
  const ClassifyConfig classes;
  return noise > 0.0 && !blocks.empty() && !isLevel(normal, classes) && !isPlumb(normal, classes) &&
         isStepped(grid, blocks, normal, noise);
}

std::vector<StepPiece> staircaseSteps(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                      const Eigen::Vector3d& normal_in, const Eigen::Vector3d& point,
                                      const StepConfig& config) {
  const Eigen::Vector3d normal = normal_in.normalized();
  if (!isStaircaseRamp(grid, blocks, normal, config.noise)) return {};
  const ClassifyConfig classes;
  const CandidatePlane reference{normal.cast<float>(), point.cast<float>()};
  Eigen::Vector3d fall(normal.x(), normal.y(), 0.0);
  fall.normalize();
  // Seen from below, a flight's steps are bands apart along its fall line; seen from
  // above, treads at their heights, touching along it: the cut that keeps more steps.
  KeptSteps bands = keptSteps(grid, stepsOf(grid, blocks, fall, std::min(grid.cellSize(), kBandWindow), true),
                              reference, config);
  // The treads are the ramp's level blocks (a riser's points spread up it): cut at their
  // heights, a riser apart at least.
  std::vector<std::uint32_t> level_blocks = blocks;
  std::erase_if(level_blocks, [&](std::uint32_t id) { return !levelBlock(grid, id, config.noise); });
  KeptSteps treads =
      level_blocks.empty()
          ? KeptSteps{}
          : keptSteps(grid, stepsOf(grid, level_blocks, Eigen::Vector3d::UnitZ(), classes.riser_min), reference, config);
  KeptSteps& chosen = treads.patches.size() > bands.patches.size() ? treads : bands;
  // One step is no staircase: a single riser whose patch took the tread's edge above it
  // (the simulated lab's and corridor's first risers at 10 cm cells) stays as it was.
  std::vector<StepPiece> pieces;
  if (chosen.patches.size() < 2) return pieces;
  for (std::size_t n = 0; n < chosen.patches.size(); ++n) {
    pieces.push_back({std::move(chosen.patches[n].blocks), chosen.patches[n].surface, std::move(chosen.planes[n])});
  }
  return pieces;
}

// Three treads, so that a riser between two level pieces (two "treads") is not a flight.
constexpr std::size_t kMinFlightTreads = 3;

bool isFlightFromAbove(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
                       const Eigen::Vector3d& point, const StepConfig& config) {
  // None where the blocks are no staircase's ramp (staircaseSteps tests that first).
  const std::vector<StepPiece> steps = staircaseSteps(grid, blocks, normal, point, config);
  const ClassifyConfig classes;
  return steps.size() >= kMinFlightTreads && std::all_of(steps.begin(), steps.end(), [&](const StepPiece& step) {
           return isLevel(step.plane.normal.normalized(), classes);
         });
}

std::size_t splitSteps(const BlockGrid& grid, PatchSet& set, const StepConfig& config, std::vector<int>* flights) {
  std::size_t cut = 0;
  const std::size_t count = set.planes.size();
  if (flights != nullptr) flights->assign(count, -1);
  for (std::size_t k = 0; k < count; ++k) {
    const Plane ramp = set.planes[k];
    std::vector<StepPiece> pieces = staircaseSteps(grid, set.blocks[k], ramp.normal, ramp.centroid, config);
    if (pieces.empty()) continue;
    Eigen::Vector3d fall(ramp.normal.x(), ramp.normal.y(), 0.0);
    fall.normalize();
    ++cut;
    for (const std::uint32_t id : set.blocks[k]) set.labels[id] = 0;  // those on no step stay so
    std::vector<std::size_t> slots;  // per step, its place in the set: the ramp's, then appended
    for (std::size_t n = 0; n < pieces.size(); ++n) {
      const std::size_t slot = n == 0 ? k : set.planes.size();
      Plane& plane = pieces[n].plane;
      plane.source = ramp.source;
      plane.candidates = ramp.candidates;
      const OutlineFrame frame{plane.normal, plane.centroid, true};
      placePatch(set, slot, std::move(plane), std::move(pieces[n].blocks), frame);
      slots.push_back(slot);
      if (flights != nullptr) {
        flights->resize(set.planes.size(), -1);
        (*flights)[slot] = static_cast<int>(k);
      }
    }
    // Then each step along its band, over blocks the ramp did not reach: within the slab a
    // step's points keep (3 σ) and across a gap of a cell (scan lines sparser than cells).
    for (const std::size_t slot : slots) {
      Plane& step = set.planes[slot];
      if (!growStep(grid, set.labels, set.blocks[slot], step, fall, 2, kMaxStepSpreadOverNoise * config.noise))
        continue;
      Patch grown;
      grown.blocks = set.blocks[slot];
      grown.surface = surfaceOf(grid, grown.blocks);
      const CandidatePlane own{step.normal.cast<float>(), step.centroid.cast<float>()};
      Plane described = describePatch(grid, grown, own, std::numbers::pi / 2, 0.0);
      described.id = step.id;
      described.source = step.source;
      described.candidates = step.candidates;
      step = std::move(described);
      set.outline_frames[slot] = OutlineFrame{step.normal, step.centroid, true};
    }
  }
  return cut;
}

}  // namespace mlmap
