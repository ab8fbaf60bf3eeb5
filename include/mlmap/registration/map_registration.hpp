// Registering one map onto another (for merging adjacent rooms): ICP between the
// surfaces the two maps' blocks describe, nearest neighbours from the OcTree key grid.
// The result says how far the maps overlap and whether the match can be trusted.
#pragma once

#include <string>
#include <vector>

#include "mlmap/map/map.hpp"
#include "mlmap/registration/icp.hpp"
#include "mlmap/registration/verified_icp.hpp"

namespace mlmap::registration {

struct MapRegistrationConfig {
  double initial_max_distance = 0.5;  // m, correspondence gate at the first ICP iteration
  double overlap_distance = 0.0;      // m, a point overlaps within this of the base; 0 = 2 cells, at least 0.1
  double min_overlap = 0.01;          // fraction of the other map's surface samples; less: unreliable
  std::size_t min_inliers = 200;
  // The start may be this far off (m) and the basin's yaw plus the retries' off in yaw.
  double max_start_translation = 1.0;
  // deg: a match that tilts the other map more is not reliable (maps are gravity-aligned; the
  // transform returned is levelled about the other map's centre either way).
  double max_tilt_deg = 1.0;
  // Both maps' walls must have a dominant direction at least this strong (wall_yaw.hpp) for
  // their turn to give the start: a room's walls at right angles read 0.81-0.98 on the stress
  // benchmark's lab, symmetric room and rooms (tune split, halves of each), directions at
  // random about 1/sqrt(walls).
  double min_wall_strength = 0.3;
  // The retries step by 10 deg: a basin of half that covers the yaw between them, at a
  // third of the search cost of 10 deg over a map's radius (the gate's cube).
  BasinConfig basin{.max_start_yaw_deg = 5.0,
                    .retry_yaw_deg = {20.0, -20.0, 10.0, -10.0, 30.0, -30.0},
                    .retry_translation = 0.6};
};

struct MapRegistration {
  Pose other_to_base = Pose::Identity();
  double rms_residual = 0.0;   // m
  double overlap = 0.0;        // fraction of the other map's surface samples near the base's
  std::size_t inliers = 0;
  std::size_t samples = 0;     // surface samples of the other map used
  bool degenerate = false;     // ICP's eigenvalue flag, for the record: `verified` decides (slide profile)
  bool verified = false;       // the result explains the overlap (see alignVerified)
  double explained_share = 0.0;  // of the other map's samples, within 3 σ of the base's surfaces
  double residual_spread = 0.0;  // m, robust spread of the residuals
  double noise = 0.0;          // m, the base map's surface noise, measured
  int attempts = 0;            // ICP runs (1 + retries)
  double tilt_deg = 0.0;       // of the ICP match, dropped from other_to_base (levelled)
  bool reliable = false;
  std::string reason;          // why not reliable; empty when reliable
};

MapRegistration registerMaps(const Map& base, const Map& other, const Pose& initial_guess,
                             const MapRegistrationConfig& config = {});

}  // namespace mlmap::registration
