// Section V's detection on a map: σ and ε resolved (measured on the map's own points
// where the build did not know them), the eRMSM blocks and their direction vectors,
// Algorithm 1 (detector.hpp), every patch classified and the labels written back.
#include "mlmap/planes/ermsm.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>

#include "bevels.hpp"
#include "creases.hpp"
#include "curved.hpp"
#include "seams.hpp"
#include "stepped.hpp"
#include "detector.hpp"
#include "median.hpp"
#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/classify.hpp"
#include "mlmap/planes/direction_vectors.hpp"
#include "patch_merges.hpp"
#include "patch_set.hpp"
#include "sheets.hpp"
#include "surface_noise.hpp"

namespace mlmap {
namespace {

// The range noise of the map's points: a vertical block keeps the variance of its
// top measurement (section IV), so their median is a measurement's. 1 cm without any.
double rangeNoise(const MLMap& map) {
  std::vector<float> variances;
  for (std::size_t n = 0; n < map.cellCount(); ++n) {
    for (const Block& block : map.blocksAt(n)) {
      if (block.isVertical()) variances.push_back(block.variance);
    }
  }
  if (variances.empty()) return 0.01;
  return std::sqrt(std::max(0.0F, medianOf(variances)));
}

// Whether the map's blocks keep their points' moments (format 3 and later).
bool hasPointStats(const MLMap& map) {
  for (std::size_t n = 0; n < map.cellCount(); ++n) {
    for (const Block& block : map.blocksAt(n)) {
      if (!block.points.empty()) return true;
    }
  }
  return false;
}

// Block heights average several points, so their scatter stays below the points':
// 3 σ. Real surfaces are not that flat over metres: on scans made elsewhere the
// points' RMS to their own plane reaches 2.1 cm (3DTK's floor), 2.6 cm (its ceiling),
// 2.3 cm (a wall of OctoMap's fr079): ε is at least min(cell, 5 cm), about two of
// those. Where blocks sit at cell centres (maps without point moments, format 2 and
// before), never less than a cell: a wall on a cell boundary has blocks half a cell
// either side of it.
double defaultEpsilon(bool at_points, double cell_size, double noise) {
  return at_points ? std::max(3.0 * noise, std::min(cell_size, 0.05))
                   : std::max(cell_size, std::min(3.0 * noise, 0.05));
}

// One family per plane for mergeCoplanar from two splits' (per plane, the index of the patch
// it was split from, -1 for none; either may be shorter than the other): the faces of one
// crease split, and the steps of one ramp. The merge after a crease split anywhere in the map
// joined the steps of fr079's flight at 10 cm cells (7 with 8, 10 to 12 into a ramp again) in
// 5 of 12 placements of the grid (bench/real_seeds.py --placements). Faces keep their family;
// a step takes its ramp's, numbered after every plane's index.
std::vector<int> keptApart(const std::vector<int>& faces_of, const std::vector<int>& flights) {
  std::vector<int> families(std::max(faces_of.size(), flights.size()), -1);
  const auto offset = static_cast<int>(families.size());
  for (std::size_t k = 0; k < families.size(); ++k) {
    if (k < faces_of.size() && faces_of[k] >= 0) {
      families[k] = faces_of[k];
    } else if (k < flights.size() && flights[k] >= 0) {
      families[k] = offset + flights[k];
    }
  }
  return families;
}

// What a detection needs before Algorithm 1: the eRMSM blocks and their direction
// vectors, with the configurations they were made with. A second pass whose σ and ε
// leave both unchanged runs on the first pass's.
struct BlockField {
  BlockGridConfig grid_config;
  DirectionConfig direction_config;
  std::optional<BlockGrid> grid;
  DirectionField directions;
};

// A level rung is fused from a few points (under ten): its variance is a good part of
// one point's σ², a table top's far below it; σ the build's, in which the blocks'
// variances are, not the one measured on the planes.
BlockGridConfig gridConfig(const ErmsmConfig& config, double block_noise) {
  return BlockGridConfig{.stack_gap = config.stack_gap,
                         .level_band = 5.0 * config.noise,
                         .ladder_gap = config.ladder_gap,
                         .ladder_blocks = config.ladder_blocks,
                         .rung_variance = 0.1 * block_noise * block_noise};
}

DirectionConfig directionConfig(const ErmsmConfig& config) {
  DirectionConfig direction_config;
  direction_config.radius = config.radius;
  // Two directions off their plane's normal by s per axis differ by more than θ in one
  // pair of twenty when s = θ / (2.45 √2) (the difference's length is Rayleigh, 95 % below 2.45 √2 s).
  direction_config.max_radius = config.max_radius > 0 ? config.max_radius : 2 * config.radius;
  direction_config.max_tilt = radians(config.theta_deg) / (2.45 * std::sqrt(2.0));
  // The widest ε a plane may take: a window narrower than the points' noise leaves
  // blocks without the neighbours that give them a direction (the simulated scenes with
  // 3 cm of noise, whose measured σ reads 1.4 cm, lost half their walls at 5 cm cells).
  direction_config.height_tolerance = static_cast<float>(std::max(config.epsilon, config.max_epsilon));
  direction_config.threads = config.threads;
  return direction_config;
}

bool sameGridConfig(const BlockGridConfig& a, const BlockGridConfig& b) {
  return a.stack_gap == b.stack_gap && a.level_band == b.level_band && a.ladder_gap == b.ladder_gap &&
         a.ladder_blocks == b.ladder_blocks && a.rung_variance == b.rung_variance;
}

// Every field the direction vectors read but the thread count (same vectors at any).
bool sameDirections(const DirectionConfig& a, const DirectionConfig& b) {
  return a.radius == b.radius && a.height_tolerance == b.height_tolerance && a.max_radius == b.max_radius &&
         a.max_tilt == b.max_tilt && a.corners == b.corners;
}

bool sameBlock(const PlaneBlock& a, const PlaneBlock& b) {
  return a.point == b.point && a.offset_x == b.offset_x && a.offset_y == b.offset_y && a.top == b.top &&
         a.bottom == b.bottom && a.surface == b.surface && a.vertical == b.vertical && a.cell.i == b.cell.i &&
         a.cell.j == b.cell.j && a.map_first == b.map_first && a.map_count == b.map_count;
}

// Two grids of one map with the same blocks of the same cells (another level band
// changes only their depth class and height): the ids whose blocks differ; nullopt where
// the grids hold other blocks.
std::optional<std::vector<std::uint32_t>> changedBlocks(const BlockGrid& a, const BlockGrid& b) {
  if (a.size() != b.size()) return std::nullopt;
  std::vector<std::uint32_t> changed;
  for (std::uint32_t id = 0; id < a.size(); ++id) {
    const PlaneBlock& x = a.blocks()[id];
    const PlaneBlock& y = b.blocks()[id];
    if (!(x.cell == y.cell) || x.map_first != y.map_first || x.map_count != y.map_count) return std::nullopt;
    if (!sameBlock(x, y)) changed.push_back(id);
  }
  return changed;
}

// The blocks and directions for `config`, made anew or, where `earlier` (a first pass's)
// already has them, taken from it: a second pass's σ moves the level band (the grid) only
// where some stack's depth lies between the two bands, and ε (the directions' height
// tolerance) only where it widens it. Either way the result is the one made anew.
BlockField blockField(const MLMap& map, const ErmsmConfig& config, double block_noise, BlockField* earlier,
                      ErmsmStats& stats, const std::function<double()>& stage) {
  BlockField field;
  field.grid_config = gridConfig(config, block_noise);
  field.direction_config = directionConfig(config);
  // The blocks that differ from the earlier grid's (all, without one).
  std::optional<std::vector<std::uint32_t>> changed;
  if (earlier != nullptr && sameGridConfig(earlier->grid_config, field.grid_config)) {
    changed.emplace();
  } else {
    field.grid.emplace(map, field.grid_config);
    ++stats.grids_built;
    if (earlier != nullptr) changed = changedBlocks(*field.grid, *earlier->grid);
  }
  if (changed && changed->empty()) field.grid = std::move(earlier->grid);
  stats.stages.grid = stage();
  if (changed && sameDirections(field.direction_config, earlier->direction_config)) {
    if (changed->empty()) {
      field.directions = std::move(earlier->directions);
    } else {
      // The blocks whose windows hold a changed block, again.
      field.directions = updatedDirectionField(*field.grid, field.direction_config, std::move(earlier->directions), *changed);
      ++stats.direction_updates;
    }
  }
  if (field.directions.vectors.empty() && field.grid->size() > 0) {
    field.directions = directionField(*field.grid, field.direction_config);
    ++stats.direction_fields;
  }
  stats.stages.directions = stage();
  return field;
}

// One detection with σ and ε resolved (config.noise, config.epsilon > 0), on `field`
// (blockField). `sheets`: σ is known, planes are cut into sheets with it.
PlaneDetection detectOn(MLMap& map, const ErmsmConfig& input_config, double block_noise, bool sheets,
                        BlockField* earlier, BlockField& field) {
  const auto start = Clock::now();
  auto stage_start = start;
  PlaneDetection detection;
  ErmsmStats& stats = detection.stats;
  // Seconds since the last call: the stage that just ended.
  const std::function<double()> stage = [&stage_start] {
    const double seconds = secondsSince(stage_start);
    stage_start = Clock::now();
    return seconds;
  };
  ErmsmConfig& config = detection.config;
  config = input_config;
  // The blocks' old labels need no clearing: the write-back at the end labels every
  // map block (each lies in one eRMSM block), 0 where no patch took it.
  stats.stages.noise = stage();
  field = blockField(map, config, block_noise, earlier, stats, stage);
  const BlockGrid& grid = *field.grid;
  const DirectionField& directions = field.directions;
  stats.direction_seconds = secondsSince(start);
  stats.blocks = grid.size();
  stats.blocks_with_direction = static_cast<std::size_t>(
      std::count_if(directions.vectors.begin(), directions.vectors.end(), [](const Eigen::Vector3f& d) { return d.squaredNorm() > 0.0F; }));

  const auto detection_start = Clock::now();
  Detector detector(grid, directions, config, sheets && hasPointStats(map));
  stats.stages.index = stage();
  PatchSet patches = detector.run(stats);
  stage();
  dropBevels(grid, patches, config.epsilon, radians(config.kappa_deg));
  // Once σ is known: compromises across shallow creases into their faces (creases.hpp).
  // A face of a split patch may lie on another patch's plane (3DTK's ceiling fixture: its
  // level face on the ceiling's): the coplanar merge again, for patches parallel within
  // κ / 3, and never two faces of one split.
  if (sheets && hasPointStats(map)) {
    // A strip of a pillar or a round wall is no plane (curved.hpp); before the crease
    // split, which would cut it into faces.
    dropCurved(grid, patches, radians(config.kappa_deg), std::max(config.epsilon, config.max_epsilon));
    std::vector<int> flights;
    splitSteps(grid, patches, {config.noise, config.min_patch_blocks, config.min_patch_area}, &flights);
    const std::vector<int> faces_of = splitCreases(
        grid, patches,
        {config.noise, config.epsilon, radians(config.kappa_deg), config.min_patch_blocks, config.min_patch_area});
    if (!faces_of.empty())
      mergeCoplanar(grid, patches, std::min(config.epsilon + 0.5 * grid.cellSize(), sheetStep(config.noise, grid.cellSize())),
                    2.0 * radians(config.kappa_deg) / 3.0, config.noise, keptApart(faces_of, flights));
  }
  // The map's surface, each block's bottom weighted by its points: whether anything lies
  // under the lowest level patch.
  std::vector<SurfaceSample> bottoms;
  bottoms.reserve(grid.size());
  for (std::size_t cell = 0; cell < grid.cellCount(); ++cell) {
    const auto blocks = map.blocksAt(grid.mapCellOf(cell));
    for (std::uint32_t id = grid.firstBlockOfCell(cell); id < grid.firstBlockOfCell(cell + 1); ++id) {
      const PlaneBlock& block = grid.blocks()[id];
      for (std::size_t k = block.map_first; k < block.map_first + block.map_count; ++k)
        bottoms.push_back({Eigen::Vector3d(block.point.x(), block.point.y(), blocks[k].bottom()),
                           std::max<double>(1.0, blocks[k].points.count)});
    }
  }
  // The steps and faces cut above have no outline yet: classification reads their extents.
  tracePendingOutlines(grid, patches, patchPassThreads(grid, config.threads));
  std::vector<std::uint8_t> landings;
  stats.height_reference = classifyPlanes(patches.planes, {}, bottoms, &landings);
  // Surfaces a step apart in one level patch (seams.hpp), once σ is known; not the floor's
  // and the ceiling's pieces, which are one level each whatever their heights (mergeLevels).
  if (sheets && hasPointStats(map))
    splitAtSeams(grid, patches,
                 {radians(config.kappa_deg), config.noise, config.min_patch_blocks, config.min_patch_area,
                  patchPassThreads(grid, config.threads)},
                 &landings);
  mergeLevels(grid, patches, radians(config.kappa_deg), sheets ? config.noise : 0.0, &landings);
  labelCeilingPieces(patches.planes, {}, landings);
  tracePendingOutlines(grid, patches, patchPassThreads(grid, config.threads));  // the merged levels'
  stats.stages.merges += stage();
  detection.planes = std::move(patches.planes);
  // The grid's frame may be centred on a map far from its origin (BlockGrid::origin): the
  // planes go back to the map's.
  if (const Eigen::Vector3d origin = grid.origin(); !origin.isZero())
    for (Plane& plane : detection.planes) movePlane(plane, origin);
  // Each cell's blocks on their own: on all threads.
  const auto cells = static_cast<std::int64_t>(grid.cellCount());
  std::size_t labelled = 0;
#pragma omp parallel for schedule(static) num_threads(teamSize(patchPassThreads(grid, config.threads))) reduction(+ : labelled)
  for (std::int64_t n = 0; n < cells; ++n) {
    const auto cell = static_cast<std::size_t>(n);
    const auto blocks = map.mutableBlocksAt(grid.mapCellOf(cell));
    for (std::uint32_t id = grid.firstBlockOfCell(cell); id < grid.firstBlockOfCell(cell + 1); ++id) {
      const PlaneBlock& block = grid.blocks()[id];
      for (std::size_t k = block.map_first; k < block.map_first + block.map_count; ++k) {
        blocks[k].plane = patches.labels[id];
        if (blocks[k].plane != 0) ++labelled;
      }
    }
  }
  stats.labelled_blocks = labelled;
  stats.stages.labels = stage();
  // Everything after the direction vectors, the labels written back included.
  stats.detection_seconds = secondsSince(detection_start);
  return detection;
}

// A pass that only measures σ: the median of surfaceNoise is the large surfaces' (the
// floor, the walls, the ceiling: most labelled blocks), found in the first few hundred
// candidates; what a search finds after 100 candidates without an acceptance is small,
// cluttered pieces, a few percent of the labelled blocks. Stopped there instead of after
// 300, the first pass draws 27-60 % of its candidates on the eight real scans of
// bench/real_data.py at 5 and 10 cm cells (3DTK at 5 cm 1164 -> 320), and the σ it
// measures moves by 2.8 % at most (not at all on 7 of those 16 maps, nor on the simulated
// lab and corridor), inside the 11-29 % that 100 blocks' median spreads anyway
// (surface_noise.hpp); no map's decision (σ moved or kept) changes. Stopped after 50 it
// moved by up to 13 % (fr079 at 10 cm) and 3DTK's at 10 cm was kept instead of moved.
ErmsmConfig measuringPass(const ErmsmConfig& config) {
  ErmsmConfig measuring = config;
  measuring.max_idle_candidates = std::min(config.max_idle_candidates, 100);
  // Nor do sparse parts (sparse_growth.hpp) join its patches: they are few blocks of
  // one or two points, whose scatter is no measure of σ.
  measuring.sparse_gap = 0.0;
  return measuring;
}

// r where none is given: the paper's 2 cells, but a window reaching at most 0.2 m out (2 cells
// of 0.1 m, the coarsest cells every constant was tried at). A wider one smooths over clutter:
// the eight real scans of bench/real_data.py at 0.15 / 0.2 / 0.25 m cells with r 1 instead of 2
// found 40 / 42 / 30 of their 64 marked surfaces instead of 41 / 41 / 30, and left 196 / 167 / 143
// patches on no marked surface instead of 261 / 240 / 177 (72 / 68 / 67 of them not flat instead
// of 97 / 96 / 103); the simulated lab and corridor at 0.2 m (bench/planes_sweep.py, turned 0,
// 10 and 30 deg) walls/floor/ceiling/tables F1 0.85-0.96 -> 0.90-0.96, none lower.
int defaultRadius(double cell_size) { return cell_size > 0.1 + 1e-9 ? 1 : 2; }

}  // namespace

// σ sets ε (3 σ), the level band (5 σ), the step between sheets (3 √2 σ) and the rung
// variance. Without --noise it is the blocks' own variance first: what the build was
// told about its measurements (3 cm for points from a file, whatever the scanner), not
// what they are. Where the blocks keep their points, the planes of that first pass then
// measure it: the median RMS distance of a block's points from its patch
// (surface_noise.hpp), about the noise the planes must tolerate, surface waviness and
// registration included. On the real scans of bench/real_data.py at 5 cm cells, against
// 3 cm assumed: 3DTK 2.3 cm, OctoMap's fr079 0.9, Bobkov's room 1.9, PCL's office1 1.2
// and room scans 1.2-1.3, plane_seg's stairs 1.0 and 0.8 (that first pass a shorter
// search: measuringPass). The planes are detected again with it (on the first pass's
// blocks and direction vectors where it leaves them as they are: blockField), σ moved
// only where it lies beyond 25 % of the first: on those eight scans the
// estimate itself moves by 16-53 % (median 28 %) between 5 and 10 cm cells, and its
// median over 100 blocks spreads -11..-29 % to +15..+41 % (95 % of 400 bootstrap draws;
// surface_noise.hpp), so a smaller difference is not a measured one.
PlaneDetection detectPlanes(MLMap& map, const ErmsmConfig& requested) {
  const auto start = Clock::now();
  ErmsmConfig input_config = requested;
  if (input_config.radius <= 0) input_config.radius = defaultRadius(map.cellSize());
  const bool at_points = hasPointStats(map);
  const double block_noise = rangeNoise(map);
  ErmsmConfig config = input_config;
  const bool measure = config.noise <= 0.0 && at_points;
  if (config.noise <= 0.0) config.noise = block_noise;
  if (config.epsilon <= 0.0) config.epsilon = defaultEpsilon(at_points, map.cellSize(), config.noise);
  // Seconds before `detection`'s own (the estimates, a first pass) count as the noise stage.
  const auto chargeNoise = [](PlaneDetection& detection, double seconds) {
    detection.stats.stages.noise += seconds;
    detection.stats.direction_seconds += seconds;
  };
  const double estimate_seconds = secondsSince(start);
  // Sheets (sheets.hpp) only with σ known: given, or measured by the first pass. From
  // the σ assumed for points from a file (3 mm for a depth camera's PCD) the first pass
  // cut PCL's office1's walls and floor into their depth layers.
  BlockField first;
  PlaneDetection detection = detectOn(map, measure ? measuringPass(config) : config, block_noise, !measure, nullptr, first);
  std::optional<double> measured = measure ? surfaceNoise(map, detection.planes) : std::nullopt;
  // Another detection on the first's blocks and directions where its σ and ε leave
  // them as they are; the seconds of the passes before count as the noise stage.
  const auto detectAgain = [&](const ErmsmConfig& again, bool sheets) {
    const double before_seconds = secondsSince(start);
    const ErmsmStats before = detection.stats;
    BlockField next;
    detection = detectOn(map, again, block_noise, sheets, &first, next);
    first = std::move(next);
    detection.stats.grids_built += before.grids_built;
    detection.stats.direction_fields += before.direction_fields;
    detection.stats.direction_updates += before.direction_updates;
    detection.stats.passes = before.passes + 1;
    chargeNoise(detection, before_seconds);
  };
  if (measure && !measured) {
    // Too few labelled blocks for the measure (small or hard maps: the test room of
    // tests/test_planes_passes.cpp with 2.5 cm noise where 3 mm were assumed): the first
    // pass again, with the whole search.
    detectAgain(config, false);
    measured = surfaceNoise(map, detection.planes);
  }
  if (!measured) {
    if (detection.stats.passes == 1) chargeNoise(detection, estimate_seconds);
    return detection;
  }
  // A depth camera's quantised depths put a surface's points on a few exact layers:
  // blocks of one layer have no scatter at all. No range sensor of the data sets
  // measures closer than a few mm (the simulated scans 4 mm).
  measured = std::max(*measured, 0.001);
  ErmsmConfig again = input_config;
  // The measurement moves σ (ε, the level band) only by more than its own uncertainty:
  // within 25 % of the first σ the first is kept. Either way the second pass cuts the
  // planes into sheets with it.
  again.noise = std::abs(std::log(*measured / config.noise)) <= std::log(1.25) ? config.noise : *measured;
  // ε follows the measured σ, also where it is narrower than the assumed one's: from
  // the 3 cm assumed for points from a file ε is 9 cm, more than half a stair's riser
  // (plane_seg's ANYmal stairs: 16.5 cm), and every tread candidate refitted into a ramp
  // through two treads. But a median over all blocks speaks for the surfaces seen best:
  // a sparse, far one (3DTK's ceiling at 5 cm cells; the 4 cm ceiling over a 1 cm floor
  // of tests/test_planes_noisy.cpp) is lost with ε from the floor's noise. So a candidate
  // whose own blocks spread too widely for it widens its ε (refitCandidate), up to the
  // ε of the larger σ, the one the first pass used.
  if (again.epsilon <= 0.0) {
    again.epsilon = defaultEpsilon(at_points, map.cellSize(), again.noise);
    if (again.max_epsilon <= 0.0) {
      again.max_epsilon = defaultEpsilon(at_points, map.cellSize(), std::max(config.noise, again.noise));
    }
  }
  detectAgain(again, true);
  if (again.noise != config.noise) detection.stats.prior_noise = config.noise;
  return detection;
}

}  // namespace mlmap
