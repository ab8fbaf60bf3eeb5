// Plane classification: floor, ceiling, wall, table, step, other, from each patch's
// orientation, height and neighbours (beyond the paper, whose planes carry no class).
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>
#include <vector>

#include "mlmap/planes/plane.hpp"

namespace mlmap {

struct ClassifyConfig {
  double horizontal_deg = 15.0;     // deg, max tilt of a horizontal patch's normal from vertical
  double level_tolerance = 0.06;    // m, a floor or ceiling patch lies this close to their height
  double table_min_height = 0.4;    // m above the floor
  double table_max_height = 1.2;    // m above the floor
  double riser_min = 0.08;          // m, height difference between neighbouring steps
  double riser_max = 0.25;          // m
  double neighbour_gap = 0.4;       // m, horizontal gap between outlines that still neighbour
  // Consecutive steps lie side by side: of the smaller, at most `max_step_overlap` lies
  // deeper than `step_overlap_depth` inside both outlines seen from above. Treads' outlines
  // overlap only along the riser, as far as they round out to cells (half a 10 cm cell
  // each, 0.1 m); a seat under a table lies well inside it.
  double step_overlap_depth = 0.1;  // m
  double max_step_overlap = 0.1;
  // m: consecutive risers of a flight lie a going apart (building codes: 0.22-0.35 m; fr079's
  // 0.30-0.35 m), drawer fronts stacked in one plane none: a riser joins a flight seen from
  // below only where the step next to it lies at least this far away across.
  double min_going = 0.1;
  double wall_min_height = 1.0;     // m, vertical extent of a wall
  double floor_search = 0.5;        // m: the floor is the largest patch this close to the lowest
  double ceiling_min_height = 1.8;  // m above the floor
  // Nothing lies under a floor: the lowest level patch is no floor where more than this
  // share of the map's surface (its points) reaches `riser_max` below its plane (a cloud cut above
  // its floor: Bobkov's room 2, whose chair seats then passed for one). Measured on the
  // floors of seven scans of ../shared/data (3DTK, fr079, office1, PCL's two rooms,
  // plane_seg's two; 5 and 10 cm cells): at most 0.13 % of the points lie 0.25 m below;
  // under Bobkov's seats 5-36 %.
  double floor_max_share_below = 0.02;
  // A flight that climbs from the floor ends on a landing or the next storey's floor: a level
  // step of at least `landing_min_area` and `landing_min_treads` times the median of the
  // flight's other level steps is floor, not a step. From a flight's geometry, not tuned: a
  // landing is at least as deep as the flight is wide (0.9 m or more), so 1 m² or more, and
  // over the common 0.28-0.30 m treads (kStepGoing's codes allow 0.22-0.35 m) it holds 3.0-3.2
  // times a tread at the least depth (a minimal landing over 0.35 m treads, 2.6 times, stays a
  // step). The one real flight with a landing in ../shared/data, plane_seg's ANYmal stairs,
  // has 3.4 m² over treads of 0.6-0.75 m² (4.6-5.7 times) at 5 and 10 cm cells.
  double landing_min_area = 1.0;   // m²
  double landing_min_treads = 3.0;
};

// A piece of the map's surface: a block's bottom, weighted by its points.
struct SurfaceSample {
  Eigen::Vector3d point;
  double weight = 1.0;
};

// Level (floor, ceiling, table, tread) and plumb (wall, riser) as classification reads a
// unit normal: within horizontal_deg of vertical, or of horizontal. Between the two: a ramp.
inline bool isLevel(const Eigen::Vector3d& normal, const ClassifyConfig& config = {}) {
  return std::abs(normal.z()) >= std::cos(config.horizontal_deg * std::numbers::pi / 180.0);
}
inline bool isPlumb(const Eigen::Vector3d& normal, const ClassifyConfig& config = {}) {
  return std::abs(normal.z()) <= std::sin(config.horizontal_deg * std::numbers::pi / 180.0);
}

// What classifyPlanes measured heights from: the floor patch, or (none in view) the lowest
// foot two or more walls share, or nothing (no table, no ceiling then).
struct HeightReference {
  enum class Kind : std::uint8_t { None, Floor, WallsFoot };
  Kind kind = Kind::None;
  double height = 0.0;  // m: z of the walls' foot (WallsFoot); 0 otherwise
};

// Sets Plane::label for every plane. The floor is the largest horizontal patch near the
// lowest one, unless the map's `surface` reaches below it; the ceiling the largest horizontal patch a storey above the floor.
// A landing that a flight from the floor climbs to is floor too, at its own height:
// `landings` (optional) gets one flag per plane, set for those.
// Without a floor, heights are measured from where two or more walls end below (a cloud cut
// above its floor); with neither, no patch is floor, ceiling or table.
HeightReference classifyPlanes(std::vector<Plane>& planes, const ClassifyConfig& config = {},
                               std::span<const SurfaceSample> surface = {},
                               std::vector<std::uint8_t>* landings = nullptr);

// After the floor's and the ceiling's pieces are merged (detectPlanes): a level patch a
// storey above the largest floor and within `riser_max` of the largest ceiling's plane
// is ceiling too, not 'other' or 'step': a higher section, or the ceiling of the room
// next door seen through a doorway, whose height the ceiling's plane gives only roughly
// that far out. Only the label changes (such a piece is no part of the ceiling's plane, so
// it is not merged into it). Hanging fixtures and ducts lie further below. The floor is
// the largest floor patch that is no landing (`landings`: one flag per plane, as
// classifyPlanes and mergeLevels leave them; empty: none): a landing may be larger than the
// floor below it, a storey's part higher.
void labelCeilingPieces(std::vector<Plane>& planes, const ClassifyConfig& config = {},
                        std::span<const std::uint8_t> landings = {});

}  // namespace mlmap
