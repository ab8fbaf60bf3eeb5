// Which way is up. The ML map stacks its blocks along z and eRMSM's classes read
// heights (section IV, V-D), so a cloud whose world frame is not z-up (a camera's
// y-down frame turned by its VIEWPOINT, a sensor mounted on its side) maps walls as
// floors. The up axis is found in the data, among the six signed coordinate axes:
//  1. the line: when the scans' rotations differ, the axis they turn about (a robot
//     turns about up only); else, when the sensors moved in a plane (a robot or a trolley
//     carries its scanner at one height; a drone flying up and down a wall would mislead
//     this), that plane's normal; else, for a depth camera's view (Scan::from_image, its
//     points in front of it), the axis its image's down lies along (sign included: a camera
//     is held with its image upright; one view faces a wall as much as the floor, and
//     PCL's office1.pcd faces its far wall most); else the axis the most
//     planar cells face (floors and ceilings, desks and seats; walls split between two
//     axes, but a long corridor's two walls outnumber its floor and ceiling);
//  2. the sign: of the points on that family's planes, more lie below their sensor
//     (floor, table tops, seats: a scanner is mounted, a camera held, nearer the floor
//     than the ceiling, and denser readings fall on the nearer surface).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "mlmap/scan.hpp"

namespace mlmap::registration {

enum class UpCue { None, Poses, Positions, Image, Planes };

struct UpAxisEstimate {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // a signed coordinate axis, world frame
  UpCue line_from = UpCue::None;  // None: too few planar cells and no turn (then up stays +z)
  double planar_share = 0.0;      // of the planar cells, the share facing the up line
  double below_share = 0.0;       // of the points on those cells, the share below their sensor
  std::size_t planar_cells = 0;
  // Planar cells enough to tell, but too few of them facing any coordinate axis (within
  // 15 deg) for a line: the data are tilted (a camera looking down at a table), up stays +z,
  // or is the image's down where that is a cue.
  bool faces_no_axis = false;
};

struct UpAxisConfig {
  double cell_size = 0.2;          // m, the cells whose points are fitted a plane
  std::size_t max_points = 200000; // the scans are thinned evenly to at most this many
};

// From scans in their sensor frames with their world poses (the sensor origins); the turn
// cue from `sequence_poses` where given (every scan's pose of a sequence of which `scans`
// holds only the first: a pose file), else from the scans' own poses.
UpAxisEstimate estimateUpAxis(const std::vector<Scan>& scans, const UpAxisConfig& config = {},
                              const std::vector<Pose>& sequence_poses = {});

// The rotation turning `up` (a signed coordinate axis) into +z: identity, a quarter
// turn about x or y, or a half turn about x.
Eigen::Matrix3d rotationToZUp(const Eigen::Vector3d& up);

// The normal of the level surfaces about the signed axis `up`: the planar cells facing it
// within 15 deg, their normals' mean without those more than 3 deg from it, on `up`'s side;
// none where fewer than 20 such cells remain. A scanner standing a few degrees off level
// tilts it off the axis, and the walls then lean across the map's cell rows.
std::optional<Eigen::Vector3d> levelNormal(const std::vector<Scan>& scans, const Eigen::Vector3d& up,
                                           const UpAxisConfig& config = {});

// The shortest rotation turning `normal` into +z (no turn about it).
Eigen::Matrix3d rotationToLevel(const Eigen::Vector3d& normal);

// "+z", "-y", ...: the axis as the CLI's --up names it.
const char* axisName(const Eigen::Vector3d& up);

}  // namespace mlmap::registration
