// Ray casting against a Scene's primitives: the nearest hit along a ray and the
// ground-truth plane id of what it hit. A brute-force loop over all primitives with the
// per-surface constants precomputed; the scenes hold a few hundred primitives at most.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "mlmap/sim/scene.hpp"

namespace mlmap::sim {

struct RayHit {
  double range = 0.0;         // m, distance from the origin along the unit direction
  std::int32_t plane_id = -1; // ground-truth plane id; -1 for a cylinder
};

class RayCaster {
 public:
  explicit RayCaster(const Scene& scene);

  // Nearest hit with range in [min_range, max_range] of the ray origin + range·direction
  // (`direction` must be unit length); surfaces are seen from both sides.
  std::optional<RayHit> cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                             double min_range = 0.0,
                             double max_range = std::numeric_limits<double>::infinity()) const;

 private:
  struct PlanarPrimitive {
    Eigen::Vector3d normal;
    double offset;        // n·corner
    Eigen::Vector3d corner;
    Eigen::Vector3d dual_u;  // (p - corner)·dual_u = s, the coordinate along edge_u
    Eigen::Vector3d dual_v;
    std::int32_t plane_id;
  };
  std::vector<PlanarPrimitive> planar_;
  std::vector<Cylinder> cylinders_;
};

}  // namespace mlmap::sim
