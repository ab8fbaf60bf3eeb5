// Internal to eRMSM's coplanar merge (patch_merges.hpp): whether the smaller of two pieces
// may be part of the larger's surface though its own fit says otherwise: the larger's noise
// tail, a piece of one long surface whose fit leans, a strip too narrow for its lean to be
// told from the noise. The joint fit (mergeCoplanar's sheet test) decides after them.
#pragma once

#include <cstddef>

#include "mlmap/map/point_stats.hpp"
#include "patch_set.hpp"

namespace mlmap {

// A parallel piece whose centroid lies `apart` m from the larger's plane, within kTailSigmas
// of the larger's RMS (piece_tests.cpp says what that was measured on).
bool isNoiseTail(const Plane& larger, double apart);

// A piece further out than that, up to kSparseTailSigmas of the larger's RMS, whose blocks
// hold under kTailDensity of the points per unit of surface of the larger's blocks within
// `radius` cells: a tail's few points, not a face sampled like the surface beside it.
bool isSparseTail(const BlockGrid& grid, const PatchSet& set, std::size_t smaller, const Plane& larger, double apart,
                  int radius);

// m: the median distance from the larger piece's plane of the smaller piece's blocks
// that lie within `radius` cells of the larger one (infinity where none does). Pieces of
// one long surface meet there though each piece's own fit leans: PCL's room_scan2 at 5 cm
// cells, a wall 10 m long in two pieces 0.8° apart, the far piece's centroid 7.7 cm off
// the near one's plane, its 72 % piece the wall's largest. Whether their points lie on one
// plane is then the sheet test's to say (mergeCoplanar).
double seamApart(const BlockGrid& grid, const PatchSet& set, std::size_t smaller, const Plane& larger, int radius);

// The largest RMS about one plane that the points of two layers of one surface can show: their
// own RMS `own`, and a sheet's step (3 √2 σ, sheets.hpp) between them, of which the joint plane
// lies half either way; σ the map's `noise`, or `own` where that is larger (mergeCoplanar says
// what it was measured on).
double oneSurfaceRms(double noise, double own);

// How far a piece may lean from the larger for withinSheet to ask (45°): a fan leans by the
// scanner's height under the surface over its distance, and where that is steep the lines
// lie close and are no strips of their own. A riser's piece beside a tread (90°, its points
// within a tread's sheet where the tread's edge blocks hold them) stays apart: the simulated
// stair at 10 cm cells (tests/test_planes_stairs.cpp) gave a tread its riser's 12 blocks.
constexpr double kMaxLeanCosine = 0.7071;
// And only a strip of a surface a tenth its size or less: a fan across a ceiling is 1-2 % of
// it (hall-4: 71-91 blocks against 4,054). Two faces of a chair 27° apart, 11 and 42 blocks,
// joined and the joint face then took a desk's points (bench/planes_sweep.py, office-67).
constexpr std::size_t kStripShare = 10;

// Whether a piece's points lie about the larger's plane within a sheet's step (mergeCoplanar's
// test for layers of one surface), whatever the piece's own fit says: a piece too narrow
// for its tilt to be told from the noise. A tilting laser's scan line far across a ceiling
// is a fan through the scanner: its range noise lies within that fan, so a strip of it one
// or two cells wide fits the fan's plane exactly (RMS 0) and leans 16-20° off the ceiling
// whose points it is (bench/planes_sweep.py's held-out hall-4 with 3 cm of range noise at
// 5 cm cells: four such patches of 71-91 points, each a false plane on the ceiling).
// Only a strip: the RMS spread of its points across its length within `width` (a cell; a
// strip up to 3.5 cells wide). Two small faces of different things side by side, 15° apart
// and each a few cells across (a chair's back by a monitor), lie within a sheet's step of
// each other's planes at 3 cm of noise, and joined (bench/planes_sweep.py, office-72).
// `piece`: its points' moments about `origin` (patchMoments).
bool withinSheet(const PointMoments& piece, const Plane& larger, const Eigen::Vector3d& origin, double noise,
                 double width);

}  // namespace mlmap
