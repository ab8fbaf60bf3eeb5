// Internal to eRMSM, beyond the paper: the patches found so far — each a Plane with
// its block ids — and the label of every block; describing a patch (its own plane
// fit, area, RMS, outline) and merging patches that are one surface.
#pragma once

#include <cstdint>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/patches.hpp"
#include "mlmap/planes/plane.hpp"
#include "outline_runs.hpp"
#include "plane_scorer.hpp"

namespace mlmap {

// The plane a patch's outline is traced on (the one it was split on, or a merged
// group's largest member's), until it is: outlines are traced after the search, all
// planes at once on all threads, since no decision of the search depends on them.
struct OutlineFrame {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  bool pending = true;
  int step = 1;  // cells per raster cell (Patch::raster_step)
};

struct PatchSet {
  std::vector<Plane> planes;                       // ids 1..n in order
  std::vector<std::vector<std::uint32_t>> blocks;  // block ids of each plane, ascending
  std::vector<OutlineFrame> outline_frames;        // per plane
  // Per plane, its raster runs on its outline frame when the split left them (empty:
  // rasterised from its blocks).
  std::vector<std::vector<Segment>> outline_runs;
  std::vector<std::int32_t> labels;                // per block id: its plane's id, 0 for none
};

// A Plane for the patch: refitted on its own blocks (two tables at slightly different
// heights keep their own offsets) unless that fit is ill-defined or leaves `reference`
// by more than κ; area, RMS, the outline moved onto the patch's own plane. Where the map
// keeps the blocks' points, the plane and RMS are their own, without the blocks whose
// points' mean lies more than 3 `noise` (σ, m; 0: all blocks) off the blocks' plane: those
// hold mostly a second surface's points. (Leaving out the blocks thicker than 2 σ along
// it instead was tried in session 37: docs/figures/planes.md.)
// A block holding one surface spreads along its normal by the noise σ; more than this many σ
// (pooled or per block) is a second surface in it (the riser in a ramp's blocks: 3.9 cm against
// 1.4 cm at fr079's 10 cm cells). describePatch fits a plane without such blocks, the staircase
// cut (stepped.hpp) tells ramps and treads by it.
inline constexpr double kOneSurfaceSpread = 2.0;

// The surface of blocks (surface units: BlockGrid's), summed in their order.
double surfaceOf(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks);

Plane describePatch(const BlockGrid& grid, const Patch& patch, const CandidatePlane& reference, double kappa_rad,
                    double noise);

// Puts a patch into the set at `slot`: in place of the plane there, or appended where `slot`
// is the set's size. The plane takes the slot's id (slot + 1) and its blocks that label, its
// outline is traced later on `frame` (pending), from no raster runs.
void placePatch(PatchSet& set, std::size_t slot, Plane plane, std::vector<std::uint32_t> blocks,
                const OutlineFrame& frame);

// Removes the patches flagged in `drop` (one flag per plane): their blocks go back to no
// patch, the others are renumbered 1..n in order and the block labels follow.
void dropPatches(PatchSet& set, const std::vector<bool>& drop);

// Traces the pending outlines (each plane on its own, on `threads` threads, 0 =
// OpenMP's default) and moves them onto their planes as describePatch would have.
void tracePendingOutlines(const BlockGrid& grid, PatchSet& set, int threads);

}  // namespace mlmap
