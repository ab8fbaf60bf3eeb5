// Openings: the crossing test is the separating-axis test of a parallelogram against a
// box; the cut works on axis-aligned rectangles in their own two in-plane coordinates.
#include "mlmap/sim/openings.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "mlmap/error.hpp"

namespace mlmap::sim {
namespace {

// m: overlaps thinner than this are touching, not crossing; thinner pieces are dropped.
constexpr double kTouch = 1e-9;

// The axis a vector lies along, if any; relative slack for cos(90°) ≈ 6e-17.
std::optional<int> alignedAxis(const Eigen::Vector3d& vector) {
  Eigen::Index axis = 0;
  const double largest = vector.cwiseAbs().maxCoeff(&axis);
  if (largest == 0.0 || vector.cwiseAbs().sum() - largest > 1e-9 * largest) return std::nullopt;
  return static_cast<int>(axis);
}

// An axis-aligned rectangle: the flat axis at `level`, [lo, hi] along the other two.
struct AxisRectangle {
  int flat = 0;
  int axis_u = 0;  // the axis of the surface's edge_u
  int axis_v = 0;
  double level = 0.0;
  Eigen::Vector3d lo = Eigen::Vector3d::Zero();
  Eigen::Vector3d hi = Eigen::Vector3d::Zero();
};

std::optional<AxisRectangle> asAxisRectangle(const Surface& surface) {
  const auto u = alignedAxis(surface.edge_u);
  const auto v = alignedAxis(surface.edge_v);
  if (!u || !v || *u == *v) return std::nullopt;
  AxisRectangle rectangle;
  rectangle.axis_u = *u;
  rectangle.axis_v = *v;
  rectangle.flat = 3 - *u - *v;
  const Eigen::Vector3d far = surface.corner + surface.edge_u + surface.edge_v;
  rectangle.lo = surface.corner.cwiseMin(far);
  rectangle.hi = surface.corner.cwiseMax(far);
  rectangle.level = surface.corner[rectangle.flat];
  return rectangle;
}

// The rectangle [lo, hi] (flat axis at the original's level) as a surface with the
// original's normal, plane id and edge axes.
Surface piece(const Surface& original, const AxisRectangle& rectangle, const Eigen::Vector3d& lo,
              const Eigen::Vector3d& hi) {
  Surface result = original;
  result.corner = lo;
  result.corner[rectangle.flat] = rectangle.level;
  result.edge_u = Eigen::Vector3d::Zero();
  result.edge_v = Eigen::Vector3d::Zero();
  result.edge_u[rectangle.axis_u] = hi[rectangle.axis_u] - lo[rectangle.axis_u];
  result.edge_v[rectangle.axis_v] = hi[rectangle.axis_v] - lo[rectangle.axis_v];
  return result;
}

// Up to four pieces around the hole: below and above it over the full width ("vertical"
// is z for a wall, y for a floor or ceiling), left and right of it beside the hole.
std::vector<Surface> cutAround(const Surface& original, const AxisRectangle& rectangle, const Opening& opening) {
  const int vertical = rectangle.flat == 2 ? 1 : 2;
  const int across = 3 - rectangle.flat - vertical;
  const Eigen::Vector3d hole_lo = rectangle.lo.cwiseMax(opening.min);
  const Eigen::Vector3d hole_hi = rectangle.hi.cwiseMin(opening.max);

  std::vector<Surface> pieces;
  auto add = [&](double across_lo, double across_hi, double vertical_lo, double vertical_hi) {
    if (across_hi - across_lo <= kTouch || vertical_hi - vertical_lo <= kTouch) return;
    Eigen::Vector3d lo = rectangle.lo;
    Eigen::Vector3d hi = rectangle.hi;
    lo[across] = across_lo;
    hi[across] = across_hi;
    lo[vertical] = vertical_lo;
    hi[vertical] = vertical_hi;
    pieces.push_back(piece(original, rectangle, lo, hi));
  };
  const double a_lo = rectangle.lo[across];
  const double a_hi = rectangle.hi[across];
  add(a_lo, a_hi, rectangle.lo[vertical], hole_lo[vertical]);           // below
  add(a_lo, a_hi, hole_hi[vertical], rectangle.hi[vertical]);           // above
  add(a_lo, hole_lo[across], hole_lo[vertical], hole_hi[vertical]);     // left
  add(hole_hi[across], a_hi, hole_lo[vertical], hole_hi[vertical]);     // right
  return pieces;
}

}  // namespace

bool crosses(const Surface& surface, const Opening& opening) {
  const std::array<Eigen::Vector3d, 4> corners = {
      surface.corner, surface.corner + surface.edge_u, surface.corner + surface.edge_u + surface.edge_v,
      surface.corner + surface.edge_v};
  const Eigen::Vector3d center = 0.5 * (opening.min + opening.max);
  const Eigen::Vector3d half = 0.5 * (opening.max - opening.min);

  std::vector<Eigen::Vector3d> axes = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                       Eigen::Vector3d::UnitZ(), surface.edge_u.cross(surface.edge_v)};
  for (int i = 0; i < 3; ++i) {
    axes.push_back(Eigen::Vector3d::Unit(i).cross(surface.edge_u));
    axes.push_back(Eigen::Vector3d::Unit(i).cross(surface.edge_v));
  }
  // Separating axes: the two overlap (by more than a touch) on every axis or not at all.
  for (const Eigen::Vector3d& raw_axis : axes) {
    const double length = raw_axis.norm();
    if (length < 1e-12) continue;
    const Eigen::Vector3d axis = raw_axis / length;
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    for (const Eigen::Vector3d& corner : corners) {
      lo = std::min(lo, axis.dot(corner));
      hi = std::max(hi, axis.dot(corner));
    }
    const double box_center = axis.dot(center);
    const double box_radius = half.dot(axis.cwiseAbs());
    if (hi <= box_center - box_radius + kTouch || lo >= box_center + box_radius - kTouch) return false;
  }
  return true;
}

void cutOpening(Scene& scene, const Opening& opening, const Placement& box_frame) {
  const Placement to_box = inverse(box_frame);
  std::vector<Surface> result;
  result.reserve(scene.surfaces.size());
  for (const Surface& surface : scene.surfaces) {
    const Surface local = transformSurface(surface, to_box);
    if (!crosses(local, opening)) {
      result.push_back(surface);
      continue;
    }
    const auto rectangle = asAxisRectangle(local);
    if (!rectangle) {
      const auto plane = scene.plane(surface.plane_id);
      throw Error("opening \"" + opening.name + "\" crosses " + (plane ? plane->name : std::string("a surface")) +
                  " (plane " + std::to_string(surface.plane_id) +
                  "), which is not an axis-aligned rectangle and cannot be cut");
    }
    for (const Surface& cut : cutAround(local, *rectangle, opening)) {
      Surface placed = transformSurface(cut, box_frame);
      placed.normal = surface.normal;
      result.push_back(placed);
    }
  }
  scene.surfaces = std::move(result);
}

}  // namespace mlmap::sim
