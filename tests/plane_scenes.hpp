// Hand-made ML maps with known planes, shared by the plane-detection tests: points
// sampled densely on rectangles with a little noise and inserted into an MLMap.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "mlmap/map/ml_map.hpp"
#include "mlmap/planes/ermsm.hpp"

namespace mlmap::test {

class PlaneSceneBuilder {
 public:
  explicit PlaneSceneBuilder(double cell_size, double noise = 0.005, unsigned seed = 1)
      : map_(cell_size), noise_(0.0, noise), random_(seed) {}

  // Samples the parallelogram corner + s·u + t·v (s, t ∈ [0, 1]) every `spacing` m.
  PlaneSceneBuilder& rectangle(const Eigen::Vector3d& corner, const Eigen::Vector3d& u,
                               const Eigen::Vector3d& v, double spacing = 0.01) {
    const int steps_u = static_cast<int>(u.norm() / spacing);
    const int steps_v = static_cast<int>(v.norm() / spacing);
    const Eigen::Vector3d normal = u.cross(v).normalized();
    for (int a = 0; a <= steps_u; ++a) {
      for (int b = 0; b <= steps_v; ++b) {
        const Eigen::Vector3d p = corner + u * (static_cast<double>(a) / steps_u) +
                                  v * (static_cast<double>(b) / steps_v) + normal * noise_(random_);
        map_.insert(p, variance_);
      }
    }
    return *this;
  }
  PlaneSceneBuilder& floor(double x0, double y0, double x1, double y1, double z) {
    return rectangle({x0, y0, z}, {x1 - x0, 0, 0}, {0, y1 - y0, 0});
  }
  // A wall x = const from y0 to y1, z0 to z1.
  PlaneSceneBuilder& wallX(double x, double y0, double y1, double z0, double z1) {
    return rectangle({x, y0, z0}, {0, y1 - y0, 0}, {0, 0, z1 - z0});
  }
  PlaneSceneBuilder& wallY(double y, double x0, double x1, double z0, double z1) {
    return rectangle({x0, y, z0}, {x1 - x0, 0, 0}, {0, 0, z1 - z0});
  }

  // The rectangles after this: points `noise` m off their plane (standard deviation),
  // inserted as measurements of variance `variance` m².
  PlaneSceneBuilder& withNoise(double noise, double variance = 1e-4) {
    noise_ = std::normal_distribution<double>(0.0, noise);
    variance_ = variance;
    return *this;
  }

  MLMap& map() { return map_; }

 private:
  MLMap map_;
  double variance_ = 1e-4;
  std::normal_distribution<double> noise_;
  std::mt19937 random_;
};

// The level patches (normal within 18° of vertical) whose centroid lies within 3 cm of
// `height`, largest first.
inline std::vector<const Plane*> levelPatchesAt(const PlaneDetection& detection, double height) {
  std::vector<const Plane*> found;
  for (const Plane& plane : detection.planes) {
    if (std::abs(plane.normal.z()) > 0.95 && std::abs(plane.centroid.z() - height) < 0.03) found.push_back(&plane);
  }
  std::sort(found.begin(), found.end(), [](const Plane* a, const Plane* b) { return a->area > b->area; });
  return found;
}

// The patches facing y (|n_y| > 0.97) whose plane lies within 5 cm of y = `y`, in the
// detection's order.
inline std::vector<const Plane*> wallPatchesAtY(const PlaneDetection& detection, double y) {
  std::vector<const Plane*> found;
  for (const Plane& plane : detection.planes) {
    if (std::abs(plane.normal.y()) > 0.97 && std::abs(plane.offset + y * plane.normal.y()) < 0.05) found.push_back(&plane);
  }
  return found;
}

}  // namespace mlmap::test
