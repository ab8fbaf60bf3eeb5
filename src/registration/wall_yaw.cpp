#include "mlmap/registration/wall_yaw.hpp"

#include <cmath>
#include <numbers>
#include <optional>

namespace mlmap::registration {
namespace {

// |n_z| below this: a wall (within 20 deg of vertical surface, sin 20 deg).
constexpr double kMaxWallNormalZ = 0.34;

double wrapQuarter(double angle) {
  const double quarter = std::numbers::pi / 2.0;
  return angle - quarter * std::floor((angle + quarter / 2.0) / quarter);
}

}  // namespace

WallYaw wallYaw(const VoxelHashMap& map, const std::vector<Point>& samples) {
  // Angles folded four times over: a wall and the walls at right angles to it (and either
  // side of each) all point the same way, and their circular mean is the dominant direction.
  double sum_cos = 0.0;
  double sum_sin = 0.0;
  WallYaw result;
  for (const Point& sample : samples) {
    const std::optional<Neighbour> neighbour = map.nearest(sample, 2.0 * map.voxelSize());
    if (!neighbour || neighbour->normal.isZero() || std::abs(neighbour->normal.z()) > kMaxWallNormalZ) continue;
    const double angle = std::atan2(neighbour->normal.y(), neighbour->normal.x());
    sum_cos += std::cos(4.0 * angle);
    sum_sin += std::sin(4.0 * angle);
    ++result.walls;
  }
  if (result.walls == 0) return result;
  result.yaw = wrapQuarter(std::atan2(sum_sin, sum_cos) / 4.0);
  result.strength = std::hypot(sum_cos, sum_sin) / static_cast<double>(result.walls);
  return result;
}

double foldedTurn(const WallYaw& from, const WallYaw& to) { return wrapQuarter(to.yaw - from.yaw); }

}  // namespace mlmap::registration
