// Internal to eRMSM, beyond the paper: no ramp through a staircase. Seen from the floor a
// staircase shows its risers and nosings, a band of scan lines every step, and a plane
// tilted at the flight's slope passes within ε of all of them (OctoMap's fr079 scan: 13
// steps of 0.13 m, one patch tilted 23° at 10 cm cells, pieces of such ramps at 5 cm).
// Its blocks tell it apart: each holds a piece of one riser, whose points spread along
// the ramp's normal by the riser's height, where a flat surface's spread by the noise.
#pragma once

#include "patch_set.hpp"

namespace mlmap {

struct StepConfig {
  double noise = 0.0;     // m, σ; 0: nothing is split or dropped
  int min_blocks = 6;     // a step's patch needs as many blocks (ErmsmConfig::min_patch_blocks)
  double min_area = 0.0;  // m², and as much surface (ErmsmConfig::min_patch_area)
};

// Each patch tilted between the classes' level and plumb tolerances
// (ClassifyConfig::horizontal_deg: a ramp is neither floor nor wall) whose blocks' points
// spread along its normal, pooled over its blocks, by more than twice σ (a flat surface's
// blocks spread by σ) is a staircase, and is cut into its
// steps where its blocks' points thin out: along its fall line between the bands a flight
// seen from below shows (risers and nosings; a window of a cell), or, where that keeps
// fewer steps, up the flight between the heights of its treads seen from above (its
// level blocks, a window of a riser, ClassifyConfig::riser_min). A step
// keeps its own patch, on its own plane, where it is as large as a patch must be and about
// as flat (its own spread within 3 σ: a step's band is an edge, its riser and nosing). With
// two such steps or more the ramp is cut: its other blocks go back to no patch, the first
// step takes its id and the others are appended; with fewer it stays as it was (one riser
// whose patch took the edge of the tread above it is no staircase). Needs the blocks'
// point moments. Returns the number of ramps cut; `flights` (optional), per plane, the index
// of the ramp its step was cut from (-1 for none): a later merge keeps them apart
// (mergeCoplanar's families), as their ramp's steps.
std::size_t splitSteps(const BlockGrid& grid, PatchSet& set, const StepConfig& config,
                       std::vector<int>* flights = nullptr);

// A staircase's step: its blocks (ascending), their surface (surface units) and its plane
// (describePatch's, on all of its blocks' points; id, source and candidates unset).
struct StepPiece {
  std::vector<std::uint32_t> blocks;
  double surface = 0.0;
  Plane plane;
};
// The steps splitSteps cuts the blocks `blocks` of a plane (`normal`, through `point`)
// into, where they are a staircase and two steps or more keep a patch; else none.
std::vector<StepPiece> staircaseSteps(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                      const Eigen::Vector3d& normal, const Eigen::Vector3d& point,
                                      const StepConfig& config);

// m: a step's going, the run from one riser to the next; the bands of a flight seen from
// below lie this far apart along it (fr079's 0.30-0.35 m, bench/stairs_bench.py's 0.30 m;
// building codes ask 0.22-0.35 m). The detector keeps a staircase's ramp in one piece
// across it (Detector::accept). fr079 at 5 cm cells, seed 1 (bench/real_data.py): steps
// found 2 of 13 with two cells' gap (0.1 m), 4 with 0.2 m, 5 with 0.3 m, 4 with 0.4 m.
inline constexpr double kStepGoing = 0.3;

// Whether blocks matching a plane (`normal`, unit) are a staircase's ramp, as splitSteps
// finds one: tilted between the classes' level and plumb tolerances, their points spread
// along it by more than twice σ (`noise`).
bool isStaircaseRamp(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
                     double noise);

// Whether blocks matching a plane (`normal`, unit, through `point`) are a flight seen from
// above: a staircase's ramp that staircaseSteps cuts into three level treads or more, with
// their risers between. Every direction window there spans a tread and its risers, so the
// search seeds ramps only and their blocks' directions spread past the 8° rule
// (bench/stairs_bench.py's stairwell seen from 1.2 m at 10 cm cells: no tread found); the
// detector does not refuse such a ramp for its spread (Detector::accept), and splitSteps
// cuts it into its treads after the search. A ramp cut into bands (fr079's flight seen from
// below) is not excused: refusing its early ramps, the search keeps those that lie through
// the whole flight (excusing every staircase ramp cost fr079 at 10 cm 6 of its steps over
// seeds 1-3, bench/real_seeds.py).
bool isFlightFromAbove(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal,
                       const Eigen::Vector3d& point, const StepConfig& config);

// The blocks' points' spread along `normal` (unit), m: the root of their scatter along it
// pooled over the blocks (each block's about its own mean), and the degrees of freedom it
// rests on (points less one per block of two points or more).
struct BlockSpread {
  double rms = 0.0;
  double dof = 0.0;
};
BlockSpread spreadAlong(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& normal);

}  // namespace mlmap
