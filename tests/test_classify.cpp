// Plane classes on maps that are not level (issue 19: "classes relative to the floor
// found"): real scans seldom are (PCL's room_scan2 2°, 3DTK's registered frame 4°).
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "mlmap/planes/classify.hpp"

using namespace mlmap;

namespace {

// A level patch of the plane with unit normal `normal` through `through`, covering
// x0..x1 × y0..y1 (its outline lifted onto the plane).
Plane levelPatch(const Eigen::Vector3d& normal, const Eigen::Vector3d& through, double x0, double x1, double y0,
                 double y1) {
  Plane plane;
  plane.normal = normal;
  plane.offset = -normal.dot(through);
  auto onPlane = [&](double x, double y) {
    return Eigen::Vector3d(x, y, -(plane.offset + normal.x() * x + normal.y() * y) / normal.z());
  };
  plane.outline = {onPlane(x0, y0), onPlane(x1, y0), onPlane(x1, y1), onPlane(x0, y1)};
  plane.centroid = onPlane((x0 + x1) / 2.0, (y0 + y1) / 2.0);
  plane.area = (x1 - x0) * (y1 - y0);
  return plane;
}

}  // namespace

TEST_CASE("Classes: a floor 2° off level, seen in two patches apart, is floor in both") {
  const double tilt = 2.0 * std::numbers::pi / 180.0;
  const Eigen::Vector3d up(-std::sin(tilt), 0.0, std::cos(tilt));
  std::vector<Plane> planes;
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.0}, 0.0, 3.0, 0.0, 2.0));   // centroid z 0.05
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.0}, 4.5, 6.0, 0.0, 2.0));   // centroid z 0.18
  planes.push_back(levelPatch(up, {0.0, 0.0, 2.5}, 0.0, 6.0, 0.0, 2.0));   // the ceiling
  planes.push_back(levelPatch(up, {0.0, 0.0, 0.75}, 4.6, 5.8, 0.2, 0.8));  // a table over the far patch
  classifyPlanes(planes);
  CHECK(planes[0].label == PlaneClass::Floor);
  CHECK(planes[1].label == PlaneClass::Floor);  // 13 cm above the first in z: 'other' before
  CHECK(planes[2].label == PlaneClass::Ceiling);
  CHECK(planes[3].label == PlaneClass::Table);
}
