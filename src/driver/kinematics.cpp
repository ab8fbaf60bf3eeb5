#include "mlmap/driver/kinematics.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "mlmap/error.hpp"
#include "mlmap/io/regular_file.hpp"

namespace mlmap::driver {
namespace {

// The chain of Fig. 2: link 1 turns the pan axis and lifts to the tilt axis, tilting its
// z onto the tilt axis (α1 = −90°); link 2 is the tilt joint, with the lateral (d2) and
// forward (a2) offsets, turning z back to the laser's spin axis (α2 = +90°); link 3 is
// the laser's rotating beam, raised by u_z (d3), whose length is the range (a3).
Eigen::Matrix4d chain(const MountConfig& mount, double pan, double tilt, double beam_angle,
                      double range) {
  const double half_pi = std::numbers::pi / 2.0;
  return dhLink(pan, mount.tilt_axis_height, 0.0, -half_pi) *
         dhLink(tilt, mount.laser_offset.y(), mount.laser_offset.x(), half_pi) *
         dhLink(beam_angle, mount.laser_offset.z(), range, 0.0);
}

}  // namespace

Eigen::Matrix4d dhLink(double theta, double d, double a, double alpha_link) {
  const double ct = std::cos(theta), st = std::sin(theta);
  const double ca = std::cos(alpha_link), sa = std::sin(alpha_link);
  Eigen::Matrix4d link;
  link << ct, -st * ca, st * sa, a * ct,  //
      st, ct * ca, -ct * sa, a * st,      //
      0.0, sa, ca, d,                     //
      0.0, 0.0, 0.0, 1.0;
  return link;
}

Beam beamAt(const MountConfig& mount, double pan, double tilt, double beam_angle) {
  const Eigen::Matrix4d transform = chain(mount, pan, tilt, beam_angle, 0.0);
  return {transform.block<3, 1>(0, 3), transform.block<3, 1>(0, 0)};
}

Point beamPoint(const MountConfig& mount, double pan, double tilt, double beam_angle, double range) {
  return chain(mount, pan, tilt, beam_angle, range).block<3, 1>(0, 3);
}

MountConfig parseMountConfig(std::string_view json_text, const std::string& source_name) {
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::exception& error) {  // parse_error, or out_of_range for 1e999
    throw Error(source_name + ": bad JSON: " + error.what());
  }
  if (!json.is_object()) throw Error(source_name + ": expected a JSON object");
  MountConfig mount;
  for (const auto& [key, value] : json.items()) {
    if (key == "tilt_axis_height") {
      if (!value.is_number() || !std::isfinite(value.get<double>())) {
        throw Error(source_name + ": tilt_axis_height: expected a number (m)");
      }
      mount.tilt_axis_height = value.get<double>();
    } else if (key == "laser_offset") {
      if (!value.is_array() || value.size() != 3) throw Error(source_name + ": laser_offset: expected 3 numbers (m)");
      for (int i = 0; i < 3; ++i) {
        if (!value[static_cast<std::size_t>(i)].is_number() ||
            !std::isfinite(value[static_cast<std::size_t>(i)].get<double>())) {
          throw Error(source_name + ": laser_offset[" + std::to_string(i) + "]: expected a number (m)");
        }
        mount.laser_offset[i] = value[static_cast<std::size_t>(i)].get<double>();
      }
    } else {
      throw Error(source_name + ": unknown field '" + key + "' (expected tilt_axis_height, laser_offset)");
    }
  }
  return mount;
}

MountConfig loadMountConfig(const std::filesystem::path& path) {
  // Read to its end: a device or a pipe never ends.
  io::refuseNonRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open");
  std::stringstream text;
  text << in.rdbuf();
  return parseMountConfig(text.str(), path.string());
}

}  // namespace mlmap::driver
