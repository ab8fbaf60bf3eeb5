// Internal to the labels (point_labels.cpp): along the edge where two patches' planes meet,
// which side of the other's plane a patch stays on. Where two surfaces meet at an edge,
// each ends at the other's plane: a wall under a ceiling lies below the ceiling's plane,
// the ceiling on the room's side of the wall's (except where a door lets it through).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "edge_choice.hpp"
#include "mlmap/planes/point_labels.hpp"
#include "mlmap/scan.hpp"

namespace mlmap {

class PatchSides {
 public:
  // The pairs of patches `outline` knows (near each other); parallel ones (cosine of their
  // normals at least `parallel_cosine`) are left out. `slot_of_point`: each point's patch
  // (0: none). `cell`: the map's cell size (m), also the length of the stretches of an edge
  // its sides are judged on. `sigmas`: the planes' tolerances in σ (a point lies past a
  // plane beyond its σ).
  PatchSides(std::span<const Point> points, std::span<const std::uint32_t> slot_of_point,
             const std::vector<PointPlane>& fitted, const OutlineReach& outline, double parallel_cosine, double cell,
             double sigmas);
  // The side of b's plane that patch a does not reach (+1: the side b's normal points to,
  // -1 the other) along the stretch of their edge where `at` lies; 0 where it reaches both
  // there or nothing tells.
  int endsAt(std::uint32_t a, std::uint32_t b, const Point& at) const;

 private:
  struct Edge {
    Eigen::Vector3d along;          // unit, along the line where the planes meet
    double start = 0.0;             // along · p where the first stretch begins
    std::vector<std::int8_t> side;  // per stretch
  };
  double stretch_;
  std::unordered_map<std::uint64_t, Edge> edges_;
};

}  // namespace mlmap
