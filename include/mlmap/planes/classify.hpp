// Plane classification: floor, ceiling, wall, table, step, other, from each patch's
// orientation, height and neighbours (beyond the paper, whose planes carry no class).
#pragma once

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
  double wall_min_height = 1.0;     // m, vertical extent of a wall
  double floor_search = 0.5;        // m: the floor is the largest patch this close to the lowest
  double ceiling_min_height = 1.8;  // m above the floor
};

// Sets Plane::label for every plane. The floor is the largest horizontal patch near the
// lowest one, the ceiling the largest horizontal patch a storey above the floor.
void classifyPlanes(std::vector<Plane>& planes, const ClassifyConfig& config = {});

}  // namespace mlmap
