// Simulated scenes for the point-label tests: every point in the world frame with its
// true plane and its scanner, the map at 5 cm and the planes detected on it.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "helpers.hpp"
#include "mlmap/map/ml_map.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "mlmap/planes/point_labels.hpp"
#include "mlmap/sim/simulator.hpp"

namespace mlmap::test {

// A simulated scene's points in the world frame, each with its true plane and the
// scanner it was seen from, mapped at 5 cm, and the planes detected on that map.
struct Scanned {
  std::vector<Point> points;
  std::vector<std::int32_t> truth;
  std::vector<Point> scanners;
  std::vector<std::uint32_t> scanner_of_point;
  MLMap map{0.05};
  PlaneDetection detection;

  // `turn_deg`: the whole scene turned about z (the map's grid stays). `range_sigma` > 0: every
  // point mapped with that range noise, as `mlmap build --range-sigma` maps scans that carry no
  // per-point variance (the simulator's .xyz files), else with the simulator's own.
  Scanned(const std::string& scene_json, const std::string& name, double turn_deg = 0.0, double range_sigma = 0.0) {
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(turn_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    for (const sim::SimulatedScan& simulated : sim::simulate(sim::parseScene(scene_json, name))) {
      const Scan& scan = simulated.scan;
      for (std::size_t k = 0; k < scan.size(); ++k) {
        points.push_back(turn * scan.worldPoint(k));
        truth.push_back(scan.labels[k]);
        scanner_of_point.push_back(static_cast<std::uint32_t>(scanners.size()));
        map.insert(points.back(), range_sigma > 0.0 ? range_sigma * range_sigma : scan.variance(k));
      }
      scanners.push_back(turn * scan.pose.translation());
    }
    detection = detectPlanes(map);
  }

  PointLabelRefinement options() const {
    return PointLabelRefinement{.noise = detection.config.noise,
                                .band = detection.config.epsilon + 0.5 * map.cellSize(),
                                .level_gap = detection.config.sparse_gap};
  }
  // As `mlmap label` with the scans' poses: the noise the planes' tolerances come from is at
  // least the one the detector assumed (labelNoiseCap).
  PointLabelRefinement labelOptions() const {
    PointLabelRefinement refinement = options();
    refinement.noise = labelNoiseCap(detection, true);
    return refinement;
  }
  BeamOrigins beams() const { return BeamOrigins{scanners, scanner_of_point}; }
  // Each point's collecting block's label (labelPoints).
  std::vector<std::int32_t> blockLabels() const {
    Scan all;
    all.points = points;
    return labelPoints(map, all);
  }
  // Each point's label refined with its scanner's beam (refinePointLabels).
  std::vector<std::int32_t> pointLabels(const PointLabelRefinement& refinement) const {
    std::vector<std::int32_t> labels = blockLabels();
    refinePointLabels(map, detection.planes, points, labels, refinement, beams());
    return labels;
  }
};

// A 6 x 5 x 2.8 m room (its floor, ceiling and walls are true planes 0-5) with the given
// poses and furniture, scanned with 1 cm of range noise at 0.5 deg beams and 1 deg lines.
inline std::string boxRoomScene(const std::string& poses, const std::string& furniture) {
  return R"({
    "scan_pattern": {"angular_step_deg": 0.5, "tilt_start_deg": -50, "tilt_end_deg": 50,
                     "tilt_step_deg": 1.0, "range_sigma": 0.01, "mount_height": 1.2},
    "poses": [)" + poses + R"(],
    "surfaces": [
      {"type": "rectangle", "class": "floor", "min": [0, 0, 0], "max": [6, 5, 0]},
      {"type": "rectangle", "class": "ceiling", "min": [0, 0, 2.8], "max": [6, 5, 2.8]},
      {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [0, 5, 2.8]},
      {"type": "rectangle", "class": "wall", "min": [6, 0, 0], "max": [6, 5, 2.8]},
      {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [6, 0, 2.8]},
      {"type": "rectangle", "class": "wall", "min": [0, 5, 0], "max": [6, 5, 2.8]},
      )" + furniture + R"(
    ]})";
}

// A width x depth x height m hall (its floor, ceiling and walls are true planes 0-5) with
// the given poses and furniture (none: empty), scanned as bench/office_rooms.py's halls are:
// a coarser laser than boxRoomScene's (0.5 deg beams, 1 deg lines, ±46 deg), 1 cm of noise
// (or `range_sigma` m).
inline std::string hallScene(double width, double depth, double height, const std::string& poses,
                             const std::string& furniture = "", double range_sigma = 0.01) {
  const auto number = [](double value) {
    std::ostringstream text;
    text << value;
    return text.str();
  };
  const std::string w = number(width), d = number(depth), h = number(height);
  return R"({
    "scan_pattern": {"angular_step_deg": 0.5, "tilt_start_deg": -46, "tilt_end_deg": 46,
                     "tilt_step_deg": 1.0, "range_sigma": )" + number(range_sigma) + R"(, "mount_height": 1.2},
    "poses": [)" + poses + R"(],
    "surfaces": [
      {"type": "rectangle", "class": "floor", "min": [0, 0, 0], "max": [)" + w + ", " + d + R"(, 0]},
      {"type": "rectangle", "class": "ceiling", "min": [0, 0, )" + h + R"(], "max": [)" + w + ", " + d + ", " + h + R"(]},
      {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [0, )" + d + ", " + h + R"(]},
      {"type": "rectangle", "class": "wall", "min": [)" + w + R"(, 0, 0], "max": [)" + w + ", " + d + ", " + h + R"(]},
      {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [)" + w + ", 0, " + h + R"(]},
      {"type": "rectangle", "class": "wall", "min": [0, )" + d + R"(, 0], "max": [)" + w + ", " + d + ", " + h + R"(]})" +
         (furniture.empty() ? "" : ",\n      " + furniture) + R"(
    ]})";
}

// Each patch's surface: the true plane most of its points lie on.
inline std::map<std::int32_t, std::int32_t> surfaceOfPatches(const std::vector<std::int32_t>& labels,
                                                      const std::vector<std::int32_t>& truth) {
  std::map<std::int32_t, std::int32_t> surface_of;
  for (const auto& [patch, by_truth] : truthByPatch(labels, truth)) surface_of[patch] = majorityTruth(by_truth);
  return surface_of;
}

// The floor's points (true plane 0) of a scanned scene, refined with its beams, and how many
// of them went to patches whose surface (surfaceOfPatches) is at least `first_surface`.
struct FloorOn {
  std::size_t floor = 0;
  std::size_t on_others = 0;
};

inline FloorOn floorPointsOn(const Scanned& scanned, std::int32_t first_surface,
                      const std::optional<PointLabelRefinement>& options = std::nullopt) {
  const std::vector<std::int32_t> labels = scanned.pointLabels(options.value_or(scanned.options()));
  std::map<std::int32_t, std::int32_t> surface_of = surfaceOfPatches(labels, scanned.truth);
  FloorOn counted;
  for (std::size_t k = 0; k < scanned.points.size(); ++k) {
    if (scanned.truth[k] != 0) continue;
    ++counted.floor;
    counted.on_others += labels[k] > 0 && surface_of[labels[k]] >= first_surface ? 1 : 0;
  }
  return counted;
}

}  // namespace mlmap::test
