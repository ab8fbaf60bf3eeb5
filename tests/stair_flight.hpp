// A floor and a flight of five steps sampled as the peers' make_scene.py samples its room
// (uniform, Gaussian noise on each axis, no scanner, no beams), mapped as `mlmap build` maps
// points that carry no variance (the UTM-30LX's 3 cm) and detected as `mlmap planes` does.
#pragma once

#include <random>
#include <vector>

#include "mlmap/map/ml_map.hpp"
#include "mlmap/planes/ermsm.hpp"

namespace mlmap::test {

struct StairFlight {
  static constexpr int kSteps = 5;
  static constexpr double kRise = 0.17, kRun = 0.28, kWidth = 1.2, kStart = 2.013, kSide = 0.027;
  // Truth 0 the floor, 1-5 the treads, 6-10 the risers, 11 the open side, 12 and 13 walls.
  static constexpr std::int32_t tread(int k) { return 1 + k; }
  static constexpr std::int32_t riser(int k) { return 1 + kSteps + k; }

  std::vector<Point> points;
  std::vector<std::int32_t> truth;
  MLMap map;
  PlaneDetection detection;

  // Neither the steps nor the sides lie on cell boundaries (as there: shifted 1.3 and 2.7 cm).
  StairFlight(double noise_sigma, double cell_size) : map(cell_size) {
    std::mt19937 random(11);
    std::normal_distribution<double> noise(0.0, noise_sigma);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    // Uniform samples of a rectangle at 2,000 points per m² (make_scene.py's default
    // room holds 500,000 points on ~270 m²): `corner` and two edge vectors.
    const auto rectangle = [&](const Point& corner, const Point& u, const Point& v, std::int32_t surface) {
      const auto count = static_cast<int>(2000.0 * u.norm() * v.norm());
      for (int k = 0; k < count; ++k) {
        points.push_back(corner + unit(random) * u + unit(random) * v + Point(noise(random), noise(random), noise(random)));
        truth.push_back(surface);
      }
    };
    const double end = kStart + kSteps * kRun;
    rectangle(Point(0, kSide, 0), Point(kStart, 0, 0), Point(0, kWidth, 0), 0);
    for (int k = 0; k < kSteps; ++k) {
      const double front = kStart + k * kRun;
      rectangle(Point(front, kSide, (k + 1) * kRise), Point(kRun, 0, 0), Point(0, kWidth, 0), tread(k));
      rectangle(Point(front, kSide, k * kRise), Point(0, 0, kRise), Point(0, kWidth, 0), riser(k));
      // The flight's open side, a staircase outline: a column per step.
      rectangle(Point(front, kSide, 0), Point(kRun, 0, 0), Point(0, 0, (k + 1) * kRise), 11);
    }
    // The walls it stands against: behind its top and along its closed side.
    rectangle(Point(end, kSide, 0), Point(0, kWidth, 0), Point(0, 0, 2.5), 12);
    rectangle(Point(0, kSide + kWidth, 0), Point(end, 0, 0), Point(0, 0, 2.5), 13);
    for (const Point& p : points) map.insert(p, kDefaultRangeVariance);
    detection = detectPlanes(map);
  }
};

}  // namespace mlmap::test
