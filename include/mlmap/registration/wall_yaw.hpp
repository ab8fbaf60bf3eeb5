// The dominant direction of a cloud's walls, folded to a quarter turn: most buildings'
// walls meet at right angles, so the turn between two clouds of the same space is their
// dominant directions' difference modulo 90 deg. Registration uses it as a start where the
// clouds' frames may differ by more yaw than one ICP run recovers (maps mapped apart share no
// frame): within ±45 deg the folded difference is the turn itself.
#pragma once

#include <vector>

#include "mlmap/registration/voxel_hash_map.hpp"
#include "mlmap/scan.hpp"

namespace mlmap::registration {

struct WallYaw {
  double yaw = 0.0;       // rad, in [-π/4, π/4): the walls' direction modulo a quarter turn
  double strength = 0.0;  // 0..1: the resultant length of the folded directions (1: all walls
                          // at right angles to each other; near 0: no dominant direction)
  std::size_t walls = 0;  // samples on a vertical surface
};

// Over `samples` (in the map's frame): the normal of `map` nearest each (within twice the
// voxel size), those within 20 deg of horizontal.
WallYaw wallYaw(const VoxelHashMap& map, const std::vector<Point>& samples);

// The folded turn from `from`'s walls to `to`'s, rad in [-π/4, π/4).
double foldedTurn(const WallYaw& from, const WallYaw& to);

}  // namespace mlmap::registration
