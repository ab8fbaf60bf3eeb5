// The scanner as a kinematic chain (section III, eq. 4, Fig. 2): Denavit–Hartenberg
// links base -> pan (α about z) -> tilt (γ about the pan frame's y, positive nose-down as
// in sim/simulator.hpp) -> laser beam (λ about the laser's spin axis), the beam itself
// being the last link of length `range`. The mounting offsets u place the laser's
// optical centre in the tilt frame. Points come out in the pan-tilt base frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <string_view>

#include "mlmap/scan.hpp"

namespace mlmap::driver {

struct MountConfig {
  double tilt_axis_height = 0.0;  // m, tilt axis above the pan base (DH d1)
  Eigen::Vector3d laser_offset = Eigen::Vector3d::Zero();  // m, u = (u_x, u_y, u_z) in the tilt frame
};

// {"tilt_axis_height": 0.05, "laser_offset": [0.0, 0.0, 0.04]} (both optional); throws
// mlmap::Error naming the file on bad JSON or fields.
MountConfig loadMountConfig(const std::filesystem::path& path);
MountConfig parseMountConfig(std::string_view json_text, const std::string& source_name);

// One standard DH link: Rot_z(θ)·Trans_z(d)·Trans_x(a)·Rot_x(α_link).
Eigen::Matrix4d dhLink(double theta, double d, double a, double alpha_link);

struct Beam {
  Eigen::Vector3d origin;     // m, base frame
  Eigen::Vector3d direction;  // unit
};

// The beam for pan α, tilt γ, beam angle λ (rad).
Beam beamAt(const MountConfig& mount, double pan, double tilt, double beam_angle);

// eq. 4: c = f(α, γ, λ, m_p, u).
Point beamPoint(const MountConfig& mount, double pan, double tilt, double beam_angle, double range);

}  // namespace mlmap::driver
