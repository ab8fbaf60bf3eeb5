#include "mlmap/registration/floor_calibration.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>

#include "mlmap/error.hpp"
#include "mlmap/io/atomic_file.hpp"
#include "mlmap/io/regular_file.hpp"

namespace mlmap::registration {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr std::size_t kMaxRansacPoints = 20000;  // inliers are counted on at most this many
constexpr std::size_t kMinFloorPoints = 100;

struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, up
  double offset = 0.0;                                // n·p + offset = 0
};

// Least-squares plane (PCA) of the points within `distance` of `plane`, oriented up.
Plane refit(const std::vector<Point>& points, const Plane& plane, double distance, std::size_t& inliers) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  inliers = 0;
  for (const Point& p : points) {
    if (std::abs(plane.normal.dot(p) + plane.offset) <= distance) {
      mean += p;
      ++inliers;
    }
  }
  if (inliers < 3) return plane;
  mean /= static_cast<double>(inliers);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Point& p : points) {
    if (std::abs(plane.normal.dot(p) + plane.offset) <= distance) covariance.noalias() += (p - mean) * (p - mean).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  Plane fitted;
  fitted.normal = solver.eigenvectors().col(0).normalized();
  if (fitted.normal.z() < 0.0) fitted.normal = -fitted.normal;
  fitted.offset = -fitted.normal.dot(mean);
  return fitted;
}

double number(const nlohmann::json& document, const char* key, const std::filesystem::path& path) {
  const auto found = document.find(key);
  if (found == document.end() || !found->is_number()) {
    throw Error(path.string() + ": " + key + ": expected a number");
  }
  return found->get<double>();
}

}  // namespace

Eigen::Matrix3d MountCorrection::rotation() const {
  return (Eigen::AngleAxisd(pitch_correction_deg * kDegree, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_correction_deg * kDegree, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

FloorCalibration calibrateFromFloor(const std::vector<Point>& points, const FloorCalibrationConfig& config) {
  // Candidates: points below the sensor, roughly where a floor can be.
  std::vector<Point> candidates;
  for (const Point& p : points) {
    if (p.allFinite() && p.z() < -config.min_depth) candidates.push_back(p);
  }
  if (candidates.size() < kMinFloorPoints) {
    throw Error("floor calibration: " + std::to_string(candidates.size()) +
                " points lie below the sensor; scan the floor around the robot");
  }
  std::vector<Point> sample;
  const std::size_t stride = candidates.size() / kMaxRansacPoints + 1;
  for (std::size_t i = 0; i < candidates.size(); i += stride) sample.push_back(candidates[i]);

  // RANSAC: planes through three sampled points, tilted at most max_tilt_deg, scored by
  // their inliers.
  std::mt19937_64 generator(config.seed);
  std::uniform_int_distribution<std::size_t> pick(0, sample.size() - 1);
  const double min_cos = std::cos(config.max_tilt_deg * kDegree);
  Plane best;
  std::size_t best_inliers = 0;
  for (int iteration = 0; iteration < config.ransac_iterations; ++iteration) {
    const Point& a = sample[pick(generator)];
    const Point& b = sample[pick(generator)];
    const Point& c = sample[pick(generator)];
    Eigen::Vector3d normal = (b - a).cross(c - a);
    if (normal.norm() < 1e-9) continue;
    normal.normalize();
    if (normal.z() < 0.0) normal = -normal;
    if (normal.z() < min_cos) continue;
    const Plane plane{normal, -normal.dot(a)};
    std::size_t inliers = 0;
    for (const Point& p : sample) inliers += std::abs(plane.normal.dot(p) + plane.offset) <= config.inlier_distance;
    if (inliers > best_inliers) {
      best_inliers = inliers;
      best = plane;
    }
  }
  if (best_inliers < kMinFloorPoints / stride + 3) {
    throw Error("floor calibration: no floor plane within " + std::to_string(config.max_tilt_deg) +
                " deg of level among " + std::to_string(candidates.size()) + " points below the sensor");
  }
  FloorCalibration result;
  Plane plane = best;
  for (int round = 0; round < 3; ++round) plane = refit(candidates, plane, config.inlier_distance, result.floor_points);
  double sum_sq = 0.0;
  for (const Point& p : candidates) {
    const double distance = plane.normal.dot(p) + plane.offset;
    if (std::abs(distance) <= config.inlier_distance) sum_sq += distance * distance;
  }
  result.rms_distance = std::sqrt(sum_sq / static_cast<double>(std::max<std::size_t>(1, result.floor_points)));
  result.floor_normal = plane.normal;
  result.floor_distance = std::abs(plane.offset);

  // R_x(roll) turns the normal into the x-z plane, then R_y(pitch) onto +z.
  const Eigen::Vector3d& n = plane.normal;
  const double roll = std::atan2(n.y(), n.z());
  const double pitch = std::atan2(-n.x(), std::hypot(n.y(), n.z()));
  result.correction.roll_correction_deg = roll / kDegree;
  result.correction.pitch_correction_deg = pitch / kDegree;
  return result;
}

void applyMountCorrection(Scan& scan, const MountCorrection& correction) {
  const Eigen::Matrix3d rotation = correction.rotation();
  for (Point& point : scan.points) point = rotation * point;
}

void writeMountCorrection(const std::filesystem::path& path, const FloorCalibration& calibration) {
  nlohmann::ordered_json document;
  document["schema"] = "mlmap.mount/1";
  document["roll_correction_deg"] = calibration.correction.roll_correction_deg;
  document["pitch_correction_deg"] = calibration.correction.pitch_correction_deg;
  document["floor_distance"] = calibration.floor_distance;
  document["floor_points"] = calibration.floor_points;
  io::writeAtomically(path, [&](std::ostream& out) { out << document.dump(2) << "\n"; });
}

MountCorrection readMountCorrection(const std::filesystem::path& path) {
  // A pipe would block the parse until its writer closes it.
  io::refuseNonRegularFile(path);
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": cannot open");
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& error) {  // parse_error, or out_of_range for 1e999
    throw Error(path.string() + ": not JSON (" + error.what() + ")");
  }
  const auto schema = document.is_object() ? document.find("schema") : document.end();
  if (schema == document.end() || !schema->is_string() || schema->get<std::string>() != "mlmap.mount/1") {
    throw Error(path.string() + ": schema: expected \"mlmap.mount/1\"");
  }
  MountCorrection correction;
  correction.roll_correction_deg = number(document, "roll_correction_deg", path);
  correction.pitch_correction_deg = number(document, "pitch_correction_deg", path);
  return correction;
}

}  // namespace mlmap::registration
