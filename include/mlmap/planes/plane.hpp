// A detected planar patch: the output of eRMSM (section V) after splitting each
// accepted plane into connected patches and classifying them.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string_view>
#include <vector>

namespace mlmap {

enum class PlaneClass : std::uint8_t { Floor, Ceiling, Wall, Table, Step, Other };

std::string_view className(PlaneClass plane_class);  // "floor", "ceiling", ...

struct Plane {
  std::int32_t id = 0;                // the label π written into the map's blocks (≥ 1)
  PlaneClass label = PlaneClass::Other;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, oriented consistently
  double offset = 0.0;                // m, n·x + offset = 0
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // m, of its blocks' points
  double area = 0.0;                  // m², its blocks' surface
  std::size_t block_count = 0;
  // m, RMS distance of its blocks' points to the plane, where σ is known without the blocks
  // whose points lie mostly on another surface (more than 3 σ off: a tread's cell holding
  // the riser below its top)
  double rms = 0.0;
  std::vector<Eigen::Vector3d> outline;  // m, boundary polygon on the plane, counter-clockwise
  // m, the box round every raster cell of the patch on its plane. A patch joins pieces across
  // small gaps (a wall seen between furniture, a sparse surface's scan lines), and its outline
  // rounds the largest piece only: Bobkov's room 2 at 5 cm, a wall 1.9 m tall whose outline
  // spans its top 1.0 m. Empty where unknown (planes read back from a file): then the outline's.
  Eigen::AlignedBox3d bounds;
  std::int32_t source = 0;            // the accepted eRMSM plane it was split from (1-based)
  std::int32_t candidates = 0;        // candidates generated before that plane was accepted
};

// The plane moved by `shift`: from a frame whose origin lies at `shift` into the one that
// frame lies in (a map's frame into the world's: MapConfig::origin), or back with −shift.
inline void movePlane(Plane& plane, const Eigen::Vector3d& shift) {
  plane.offset -= plane.normal.dot(shift);
  plane.centroid += shift;
  for (Eigen::Vector3d& corner : plane.outline) corner += shift;
  if (!plane.bounds.isEmpty()) plane.bounds.translate(shift);
}

}  // namespace mlmap
