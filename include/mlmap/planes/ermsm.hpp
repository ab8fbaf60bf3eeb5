// eRMSM, efficient RANSAC in Multilevel Surface Maps (section V): Algorithm 1 with
// candidates seeded from three neighbouring blocks of similar direction, scored in
// surface units, refitted by PCA (Algorithm 2) and accepted by eq. 10.
// Deterministic for a given seed at any thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "mlmap/map/ml_map.hpp"
#include "mlmap/planes/classify.hpp"
#include "mlmap/planes/plane.hpp"

namespace mlmap {

struct ErmsmConfig {
  // cells, Chebyshev radius r (direction vectors, candidate seeds); 0 = 2, and 1 where a cell is
  // wider than 0.1 m (defaultRadius: a window at most 0.2 m out)
  int radius = 0;
  // cells: a level block's direction window widens up to this where r cells leave its
  // normal uncertain (standard error over θ / 3.5: noisy or sparse surfaces); 0 = 2 r
  int max_radius = 0;
  // m, max block-plane distance ε; 0 = max(3 σ, min(cell size, 0.05)) (maps without point
  // moments: max(cell size, min(3 σ, 0.05)))
  double epsilon = 0.0;
  // m: a plane whose blocks spread too widely for ε widens its own up to this (their
  // noise, not the median surface's); 0 = ε. Set where σ was measured: ε from the
  // measured σ, this from the σ assumed before.
  double max_epsilon = 0.0;
  // m, σ of the points' range noise; 0 = measured: the median of the map's vertical
  // blocks' σ, then, where the blocks keep their points, about the planes found with it
  double noise = 0.0;
  // m: consecutive blocks of a cell closer than this are one eRMSM block (a wall's stack
  // between scan lines in cells finer than their spacing); a stack no deeper than
  // max(cell size, 5 σ) counts as level. It acts only where the map's cells are finer
  // than it (a map block ends at a gap of a cell). On bench/real_data.py's 8 scans at 5 cm
  // cells (2026-12-04, seed 1), 0.04 / 0.06 / 0.08 / 0.10: surfaces found 41 / 44 / 44 / 45
  // of 64, RMS within 0.5 cm 47 / 43 / 48 / 49; every step swaps surfaces (0.10: fr079's
  // lowest step bands found, room_scan2's walls y3.09 and x-2.55 lost; 0.08: room_scan2's
  // x8.02 lost, its y3.09 found), so 0.06 stays; the scan-line spacing it stands for is
  // not measured yet.
  double stack_gap = 0.06;
  // m: a ladder of at least ladder_blocks short blocks of a cell, each less than this
  // apart, is one eRMSM block too (a surface seen at a grazing angle or far away,
  // its scan lines further apart than the stack gap); 0 = no ladders. On bench/real_data.py's
  // 8 scans (2026-12-04, seed 1), 0.1 / 0.15 / 0.2 / 0.3: surfaces found 42 / 43 / 44 / 41 of
  // 64 at 5 cm cells and 37 / 38 / 44 / 41 at 10 cm (far walls and treads seen as a few scan
  // lines need 0.2; why 0.3 loses three was not looked into).
  double ladder_gap = 0.2;
  // Four: two or three short blocks that far apart are as likely a shelf or a seat over a
  // step (BlockGridConfig). Six, as before, left walls seen as four or five scan lines as
  // rungs (Bobkov's room 2 above its sideboard, fr079's walls and the PCL room scans' far
  // walls at 10 cm cells, ANYmal's treads at 10 cm: bench/real_seeds.py, seeds 1-3, found
  // 111 / 103 -> 114 / 116 of 192 at 5 / 10 cm; three rungs 113 / 114).
  int ladder_blocks = 4;
  double kappa_deg = 25.0;        // deg, max angle between a block's direction and the plane, κ
  double theta_deg = 15.0;        // deg, max angle between the three seeds' directions, θ
  double min_probability = 0.99;  // p_t of eq. 10's acceptance test
  // k in eq. 10's P = (s_c / s_o)^k. The paper cubes the ratio, as if all three seeds
  // were drawn from the whole map; here only the first is, the other two are its
  // neighbours, so one power counts the draw. With 3, planes of a few percent of
  // their orientation's surface (stair treads, risers) are never accepted.
  double acceptance_exponent = 1.0;
  double min_area = 0.15;         // m², s_m: a plane's minimal matched surface
  double min_patch_area = 0.15;   // m², smaller connected patches go back to the pool
  int min_patch_blocks = 6;       // fit points (a level block one, a vertical block two), and so do patches of fewer
  double min_patch_width_cells = 0.7;  // cells, and patches whose blocks spread less across (std-dev)
  // cells, the same for level patches: two rows of cells (a spread of 0.5) are enough. A
  // stair tread or a bench top against a wall is two cells deep at 10 cm cells; the
  // slivers the width rule is for are walls in room corners, where directions turn.
  double min_level_patch_width_cells = 0.45;
  // deg, mean angle of a plane's blocks to its normal (curved surfaces fail); for level
  // planes beyond what the noise of their blocks' directions gives (the two add in
  // squares): where a surface's points scatter by a good part of a cell (3DTK's ceiling at
  // 5 cm) noise alone spreads its directions by more than 8°.
  double max_direction_spread_deg = 8.0;
  // m: after the search, a patch takes the blocks of its surface that no window could
  // give a direction (scan lines further apart than it), each within this of the patch
  // or of one that joined, across gaps nothing was seen past (sparse_growth.hpp); 0 = off.
  // 0.6: the widest scan-line spacing on the floors of PCL's two room scans 5-7 m out
  // (0.35-0.7 m); on bench/real_data.py 0.4 found 35 / 32 of 64 surfaces (5 / 10 cm
  // cells), 0.6 35 / 34 (Bobkov's room 2: its wall x-1.71 at 10 cm 31 -> 92 %), 1.0 no more.
  // Then the sparse surfaces no patch reached are searched with neighbourhoods of it
  // (sparse_search.hpp: a block's local plane from those within half of it, a region
  // grown across it).
  double sparse_gap = 0.6;
  int max_candidates = 4000;      // Max_cp: Algorithm 1 stops after this many candidates
  int max_idle_candidates = 300;  // ... or after this many without an accepted plane
  int batch_size = 16;            // candidates per iteration of Algorithm 1 (fixed, not per thread)
  int max_refits = 5;             // Algorithm 2's iterations at most
  double refit_gain = 1.0;        // surface units: Algorithm 2 stops when a refit gains less
  std::uint64_t seed = 1;         // same seed, same planes, at any thread count
  int threads = 0;                // OpenMP threads; 0 = OpenMP's default
};

// Seconds per stage of detectPlanes, for profiling: the first three make up
// ErmsmStats::direction_seconds, the rest detection_seconds.
struct ErmsmStageSeconds {
  double noise = 0.0;       // the range-noise estimate
  double grid = 0.0;        // eRMSM blocks (BlockGrid)
  double directions = 0.0;  // direction vectors
  double index = 0.0;       // the scorer's index, the seedable blocks
  double search = 0.0;      // Algorithm 1: draws, scores, refits, acceptance tests
  double patches = 0.0;     // accepted planes: matching and edge blocks, patch split; the patches' descriptions and outlines
  double merges = 0.0;      // coplanar merges, classification, level merges (their outlines)
  double labels = 0.0;      // labels written back into the map's blocks
};

struct ErmsmStats {
  std::size_t blocks = 0;
  std::size_t blocks_with_direction = 0;
  std::size_t candidates = 0;          // generated in all
  std::size_t scored = 0;              // fully scored (the rest re-found a listed plane)
  std::size_t accepted = 0;            // accepted eRMSM planes (before the patch split)
  std::size_t labelled_blocks = 0;
  // m: where σ was measured on a first pass's planes (see detectPlanes), that pass's σ;
  // 0 where one pass sufficed
  double prior_noise = 0.0;
  // detections run: 2 where σ was measured on a first pass's planes (3 where that pass's
  // shorter search left too few blocks to measure it on, and the whole search ran)
  int passes = 1;
  // eRMSM block grids and direction fields made, over all passes: a second pass makes
  // neither where its σ and ε leave them as the first pass's (detectPlanes)
  int grids_built = 0;
  int direction_fields = 0;
  // direction fields brought up to date from an earlier pass's where σ changed some
  // blocks only (updatedDirectionField: the blocks near them, or all where those are most)
  int direction_updates = 0;
  // The largest wall-like plane the direction-spread rule refused (of the final pass): the
  // surface of the blocks that matched it (m²) and their spread (deg; 0: none refused). A
  // dense cloud with range noise a good part of a cell spreads its walls' directions past
  // the rule (see README's weak spots); `mlmap planes` says so.
  double refused_wall_area = 0.0;
  double refused_wall_spread_deg = 0.0;
  // What the classes measured heights from (classify.hpp): the floor, the walls' shared foot
  // (a cloud cut above its floor; `mlmap planes` says so), or nothing.
  HeightReference height_reference;
  double direction_seconds = 0.0;   // noise estimate, eRMSM blocks and direction vectors
  double detection_seconds = 0.0;   // Algorithm 1 with refits, patch split, merges, classes, labels
  ErmsmStageSeconds stages;         // both, split further
};

struct PlaneDetection {
  std::vector<Plane> planes;  // patches, ids 1..n in the order found
  ErmsmStats stats;
  ErmsmConfig config;         // with the defaults resolved (ε)
};

// Detects the planes of `map` and writes each block's patch id into Block::plane
// (0 for none; labels from an earlier run are cleared first). Without config.noise and
// where the blocks keep their points, σ is measured on the planes a first pass finds
// and, if it differs from the blocks' own by more than 25 %, the planes are detected
// again with it (ErmsmStats::prior_noise says so).
PlaneDetection detectPlanes(MLMap& map, const ErmsmConfig& config = {});

}  // namespace mlmap
