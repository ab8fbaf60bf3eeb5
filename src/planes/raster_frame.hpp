// Internal to eRMSM: the raster a plane's blocks are split into patches and outlined on.
//
// A plane in general is rasterised on its own basis (planeBasis), cells counted from a
// point of it: a block's cell is where its point projects. A level plane (a floor, a
// ceiling, a table top, a step) is rasterised on the map's own grid seen from above
// instead: a block's cell is the map cell it lies in, with u its row i and v its column
// j, counted from the grid's origin cell (BlockGrid::localCell). Its blocks, numbered row by row over the grid, then come in raster order already,
// so the split sorts nothing, and no point is projected. A plane is level where
// planeBasis cannot take u = z × n (|z × n| < kLevelSine, within 17.5° of level): there
// a cell of the grid is at most 1.05 times longer on the plane than on its own raster,
// so the gaps that join patches mean the same; and every other plane has a level u, so
// a vertical block's cells there are one run (of v, at the u of its point).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

#include "mlmap/planes/patches.hpp"

namespace mlmap {

struct RasterFrame {
  static constexpr double kLevelSine = 0.3;

  Eigen::Vector3d normal;
  Eigen::Vector3d point;
  double cell_size;
  bool on_map_grid;        // a level plane
  Eigen::Vector3d u_axis;  // the plane's basis; unused on the map grid
  Eigen::Vector3d v_axis;

  RasterFrame(const Eigen::Vector3d& plane_normal, const Eigen::Vector3d& plane_point, double cell)
      : normal(plane_normal),
        point(plane_point),
        cell_size(cell),
        on_map_grid(Eigen::Vector3d::UnitZ().cross(plane_normal).norm() < kLevelSine) {
    planeBasis(normal, u_axis, v_axis);
  }

  // The raster corner (u, v) (the low corner of cell (u, v)) on the plane. On the map
  // grid that is the corner (x, y) = (v, u) cells of the map's cell (i, j) = (u, v),
  // lifted along z onto the plane.
  Eigen::Vector3d corner(std::int32_t u, std::int32_t v) const {
    if (!on_map_grid) return point + u_axis * (u * cell_size) + v_axis * (v * cell_size);
    const double x = v * cell_size;
    const double y = u * cell_size;
    return {x, y, point.z() - (normal.x() * (x - point.x()) + normal.y() * (y - point.y())) / normal.z()};
  }

  // Whether a loop counter-clockwise in (u, v) runs counter-clockwise about the normal:
  // on the plane's basis always (u × v = normal); on the map grid, where (u, v) is
  // (y, x), only about a normal pointing down.
  bool keepsTurn() const { return !on_map_grid || normal.z() < 0.0; }
};

}  // namespace mlmap
