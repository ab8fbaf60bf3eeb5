// Openings: doors and windows cut out of a scene's surfaces ("openings" in
// maps/README.md). An opening is an axis-aligned box; every axis-aligned rectangle that
// reaches into it is split into up to four rectangles around the hole (below, above,
// left, right). The pieces keep the plane id, so the ground truth is unchanged.
#pragma once

#include <Eigen/Core>
#include <string>

#include "mlmap/sim/placement.hpp"
#include "mlmap/sim/scene.hpp"

namespace mlmap::sim {

struct Opening {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();  // m, scene frame
  Eigen::Vector3d max = Eigen::Vector3d::Zero();  // m
  std::string name = "opening";
};

// Whether the surface reaches into the opening's interior, both in one frame; touching
// a face (a floor under a door, a door's jamb) does not count.
bool crosses(const Surface& surface, const Opening& opening);

// Cuts the opening out of every surface that crosses it; the opening is a box in the
// frame placed at `box_frame` in the scene's, and the surfaces it cuts must be
// axis-aligned rectangles in that frame (else mlmap::Error naming the opening and the
// plane). Surfaces it does not cross are left exactly as they are.
void cutOpening(Scene& scene, const Opening& opening, const Placement& box_frame = {});

}  // namespace mlmap::sim
