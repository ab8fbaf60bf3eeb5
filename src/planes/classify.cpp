#include "mlmap/planes/classify.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

namespace mlmap {
namespace {

struct Extent {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d max = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
};

Extent extentOf(const Plane& plane) {
  Extent extent;
  for (const Eigen::Vector3d& p : plane.outline) {
    extent.min = extent.min.cwiseMin(p);
    extent.max = extent.max.cwiseMax(p);
  }
  if (plane.outline.empty()) extent.min = extent.max = plane.centroid;
  return extent;
}

bool neighbours(const Extent& a, const Extent& b, double gap) {
  return a.min.x() - gap <= b.max.x() && b.min.x() - gap <= a.max.x() &&
         a.min.y() - gap <= b.max.y() && b.min.y() - gap <= a.max.y();
}

}  // namespace

std::string_view className(PlaneClass plane_class) {
  switch (plane_class) {
    case PlaneClass::Floor: return "floor";
    case PlaneClass::Ceiling: return "ceiling";
    case PlaneClass::Wall: return "wall";
    case PlaneClass::Table: return "table";
    case PlaneClass::Step: return "step";
    case PlaneClass::Other: break;
  }
  return "other";
}

void classifyPlanes(std::vector<Plane>& planes, const ClassifyConfig& config) {
  const double cos_horizontal = std::cos(config.horizontal_deg * std::numbers::pi / 180.0);
  const double sin_vertical = std::sin(config.horizontal_deg * std::numbers::pi / 180.0);
  std::vector<std::size_t> horizontal;
  std::vector<Extent> extents;
  for (std::size_t k = 0; k < planes.size(); ++k) {
    extents.push_back(extentOf(planes[k]));
    if (std::abs(planes[k].normal.z()) >= cos_horizontal) horizontal.push_back(k);
  }
  // The floor: the largest horizontal patch among the lowest ones; the ceiling: the
  // largest one a storey above it.
  std::optional<double> floor_z;
  std::optional<double> ceiling_z;
  double lowest = std::numeric_limits<double>::infinity();
  for (const std::size_t k : horizontal) lowest = std::min(lowest, planes[k].centroid.z());
  double floor_area = 0.0;
  for (const std::size_t k : horizontal) {
    if (planes[k].centroid.z() <= lowest + config.floor_search && planes[k].area > floor_area) {
      floor_area = planes[k].area;
      floor_z = planes[k].centroid.z();
    }
  }
  double ceiling_area = 0.0;
  for (const std::size_t k : horizontal) {
    if (floor_z && planes[k].centroid.z() >= *floor_z + config.ceiling_min_height &&
        planes[k].area > ceiling_area) {
      ceiling_area = planes[k].area;
      ceiling_z = planes[k].centroid.z();
    }
  }
  auto near = [&](const std::optional<double>& level, double z) {
    return level && std::abs(z - *level) < config.level_tolerance;
  };
  // Horizontal patches first: risers and steps refer to them.
  for (const std::size_t k : horizontal) {
    Plane& plane = planes[k];
    const double z = plane.centroid.z();
    if (near(floor_z, z)) {
      plane.label = PlaneClass::Floor;
    } else if (near(ceiling_z, z)) {
      plane.label = PlaneClass::Ceiling;
    } else {
      bool step = false;
      for (const std::size_t other : horizontal) {
        const double rise = std::abs(planes[other].centroid.z() - z);
        if (other != k && rise >= config.riser_min && rise <= config.riser_max &&
            neighbours(extents[k], extents[other], config.neighbour_gap)) {
          step = true;
        }
      }
      const double above_floor = floor_z ? z - *floor_z : 0.0;
      if (step && (!ceiling_z || z < *ceiling_z - config.riser_max)) {
        plane.label = PlaneClass::Step;
      } else if (floor_z && above_floor >= config.table_min_height && above_floor <= config.table_max_height) {
        plane.label = PlaneClass::Table;
      } else {
        plane.label = PlaneClass::Other;
      }
    }
  }
  for (std::size_t k = 0; k < planes.size(); ++k) {
    Plane& plane = planes[k];
    if (std::abs(plane.normal.z()) >= cos_horizontal) continue;
    if (std::abs(plane.normal.z()) > sin_vertical) {
      plane.label = PlaneClass::Other;
      continue;
    }
    const double height = extents[k].max.z() - extents[k].min.z();
    if (height >= config.wall_min_height) {
      plane.label = PlaneClass::Wall;
      continue;
    }
    // A riser: low, between a step and the floor or another step.
    plane.label = PlaneClass::Other;
    if (height <= config.riser_max + config.level_tolerance) {
      for (const std::size_t other : horizontal) {
        if (planes[other].label == PlaneClass::Step &&
            std::abs(planes[other].centroid.z() - extents[k].max.z()) < config.level_tolerance + 0.05 &&
            neighbours(extents[k], extents[other], config.neighbour_gap)) {
          plane.label = PlaneClass::Step;
        }
      }
    }
  }
}

}  // namespace mlmap
