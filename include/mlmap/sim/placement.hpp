// Placement of one scene's frame in another's, for scene includes ("include" in
// maps/README.md: e.g. the lab beside the corridor with a door between them, each mapped
// in its own frame so that the two maps can be joined as in the paper's Fig. 11), and
// the rigid motion of a surface or a whole scene. loadScene (scene.hpp) reads includes.
#pragma once

#include "mlmap/scan.hpp"
#include "mlmap/sim/scene.hpp"

namespace mlmap::sim {

// Where a scene's frame lies in another's: a turn about z, then a translation in x, y.
// Maps a point p of the placed frame to R(yaw)·p + (x, y, 0).
struct Placement {
  double x = 0.0;        // m
  double y = 0.0;        // m
  double yaw_deg = 0.0;  // deg, counter-clockwise from +x
};

// `outer` after `inner`: a frame placed by `inner` inside a frame placed by `outer`.
Placement compose(const Placement& outer, const Placement& inner);
Placement inverse(const Placement& placement);
bool isIdentity(const Placement& placement);
Pose toPose(const Placement& placement);  // the 4 × 4 rigid motion

// Moves every surface, cylinder, ground-truth plane and robot pose of `scene` by
// `placement`. Turns by multiples of 90° are exact and positions are rounded to the
// nanometre (22 + 8.3 - 22 reads 8.3); the identity changes nothing.
void transformScene(Scene& scene, const Placement& placement);
Surface transformSurface(const Surface& surface, const Placement& placement);

}  // namespace mlmap::sim
