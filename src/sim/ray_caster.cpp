#include "mlmap/sim/ray_caster.hpp"

#include <cmath>

namespace mlmap::sim {
namespace {

// Parameter slack so that rays through a shared edge (floor pieces, room corners) hit
// one of the two surfaces instead of slipping between them.
constexpr double kEdgeSlack = 1e-9;

}  // namespace

RayCaster::RayCaster(const Scene& scene) : cylinders_(scene.cylinders) {
  planar_.reserve(scene.surfaces.size());
  for (const Surface& surface : scene.surfaces) {
    PlanarPrimitive primitive;
    const Eigen::Vector3d normal = surface.edge_u.cross(surface.edge_v).normalized();
    primitive.normal = normal;
    primitive.corner = surface.corner;
    primitive.offset = normal.dot(surface.corner);
    // Dual basis of (edge_u, edge_v) within the plane: dual_u·edge_u = 1, dual_u·edge_v = 0.
    const Eigen::Vector3d v_perp = surface.edge_v.cross(normal);
    const Eigen::Vector3d u_perp = normal.cross(surface.edge_u);
    primitive.dual_u = v_perp / surface.edge_u.dot(v_perp);
    primitive.dual_v = u_perp / surface.edge_v.dot(u_perp);
    primitive.plane_id = surface.plane_id;
    planar_.push_back(primitive);
  }
}

std::optional<RayHit> RayCaster::cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                      double min_range, double max_range) const {
  double best = max_range;
  std::int32_t best_id = -1;
  bool found = false;

  for (const PlanarPrimitive& primitive : planar_) {
    const double denominator = primitive.normal.dot(direction);
    if (denominator == 0.0) continue;  // parallel: a grazing ray sees no area
    const double range = (primitive.offset - primitive.normal.dot(origin)) / denominator;
    if (!(range >= min_range && range <= best)) continue;
    const Eigen::Vector3d local = origin + range * direction - primitive.corner;
    const double s = primitive.dual_u.dot(local);
    if (s < -kEdgeSlack || s > 1.0 + kEdgeSlack) continue;
    const double t = primitive.dual_v.dot(local);
    if (t < -kEdgeSlack || t > 1.0 + kEdgeSlack) continue;
    best = range;
    best_id = primitive.plane_id;
    found = true;
  }

  // Vertical cylinders: |(o + r·d)_xy - c|² = radius², the smaller root outside, the
  // larger one from inside.
  const double a = direction.x() * direction.x() + direction.y() * direction.y();
  if (a > 0.0) {
    for (const Cylinder& cylinder : cylinders_) {
      const double ox = origin.x() - cylinder.center.x();
      const double oy = origin.y() - cylinder.center.y();
      const double b = ox * direction.x() + oy * direction.y();
      const double c = ox * ox + oy * oy - cylinder.radius * cylinder.radius;
      const double discriminant = b * b - a * c;
      if (discriminant < 0.0) continue;
      const double root = std::sqrt(discriminant);
      for (const double range : {(-b - root) / a, (-b + root) / a}) {
        if (!(range >= min_range && range <= best)) continue;
        const double z = origin.z() + range * direction.z();
        if (z < cylinder.z_min || z > cylinder.z_max) continue;
        best = range;
        best_id = -1;
        found = true;
        break;
      }
    }
  }

  if (!found) return std::nullopt;
  return RayHit{best, best_id};
}

}  // namespace mlmap::sim
