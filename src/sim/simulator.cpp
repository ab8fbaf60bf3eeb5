#include "mlmap/sim/simulator.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <numbers>
#include <nlohmann/json.hpp>
#include <string>

#include "mlmap/error.hpp"
#include "mlmap/io/atomic_file.hpp"
#include "mlmap/io/tum_poses.hpp"
#include "mlmap/io/xyz.hpp"
#include "mlmap/sim/ray_caster.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap::sim {
namespace {

// splitmix64 (Steele et al. 2014): a small generator whose stream is the same on every
// platform, unlike std::normal_distribution's.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}

  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)

  // Standard normal by Box–Muller, the second value kept for the next call.
  double gaussian() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    const double radius = std::sqrt(-2.0 * std::log(u1));
    const double angle = 2.0 * std::numbers::pi * u2;
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

 private:
  std::uint64_t state_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

std::uint64_t mixSeed(std::uint64_t seed, std::uint64_t a, std::uint64_t b) {
  Random mixer(seed ^ 0x5851f42d4c957f2dULL);
  std::uint64_t value = mixer.next() ^ (a * 0xd1342543de82ef95ULL);
  value = Random(value).next() ^ (b * 0x9e3779b97f4a7c15ULL);
  return Random(value).next();
}

struct ScanLine {
  std::vector<Point> points;
  std::vector<double> variances;
  std::vector<std::int32_t> labels;
};

// One tilt line: every beam of the 2D laser at tilt `line` (eq. 4 with α = 0).
void castLine(const Scene& scene, const RayCaster& caster, const Pose& pose, std::size_t pose_index,
              std::size_t line, const std::vector<Eigen::Vector2d>& beam_cos_sin, bool range_noise,
              ScanLine& out) {
  const ScanPattern& pattern = scene.pattern;
  const double tilt = pattern.tiltAngle(line);
  const double cos_tilt = std::cos(tilt);
  const double sin_tilt = std::sin(tilt);
  const Eigen::Matrix3d rotation = pose.linear();
  const Eigen::Vector3d origin = pose.translation();
  Random random(mixSeed(pattern.seed, pose_index, line));

  out.points.reserve(beam_cos_sin.size());
  out.variances.reserve(beam_cos_sin.size());
  out.labels.reserve(beam_cos_sin.size());
  for (const Eigen::Vector2d& cos_sin : beam_cos_sin) {
    const Eigen::Vector3d direction(cos_tilt * cos_sin.x(), cos_sin.y(), -sin_tilt * cos_sin.x());
    const auto hit = caster.cast(origin, rotation * direction, pattern.min_range, pattern.max_range);
    if (!hit) continue;
    const double sigma = pattern.rangeSigma(hit->range);
    const double range = range_noise ? hit->range + sigma * random.gaussian() : hit->range;
    out.points.push_back(range * direction);
    out.variances.push_back(sigma * sigma);
    out.labels.push_back(hit->plane_id);
  }
}

Pose robotPose(double x, double y, double yaw, double mount_height) {
  Pose pose = Pose::Identity();
  pose.translation() = Eigen::Vector3d(x, y, mount_height);
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return pose;
}

double wrapAngle(double angle) { return std::remainder(angle, 2.0 * std::numbers::pi); }

void writeNumber(std::string& out, double value) {
  std::array<char, 64> buffer;
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value,
                                    std::chars_format::fixed, 6);
  out.append(buffer.data(), result.ptr);
}

}  // namespace

Scan simulateScan(const Scene& scene, const Pose& pose, std::size_t pose_index,
                  const SimulateOptions& options) {
  const ScanPattern& pattern = scene.pattern;
  const RayCaster caster(scene);
  std::vector<Eigen::Vector2d> beam_cos_sin(pattern.beamCount());
  for (std::size_t beam = 0; beam < beam_cos_sin.size(); ++beam) {
    const double angle = pattern.beamAngle(beam);
    beam_cos_sin[beam] = {std::cos(angle), std::sin(angle)};
  }

  const auto line_count = static_cast<std::ptrdiff_t>(pattern.lineCount());
  std::vector<ScanLine> lines(static_cast<std::size_t>(line_count));
#ifdef _OPENMP
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
#endif
  for (std::ptrdiff_t line = 0; line < line_count; ++line) {
    const auto index = static_cast<std::size_t>(line);
    castLine(scene, caster, pose, pose_index, index, beam_cos_sin, options.range_noise, lines[index]);
  }

  Scan scan;
  scan.pose = pose;
  std::size_t total = 0;
  for (const ScanLine& line : lines) total += line.points.size();
  scan.points.reserve(total);
  scan.variances.reserve(total);
  scan.labels.reserve(total);
  for (const ScanLine& line : lines) {
    scan.points.insert(scan.points.end(), line.points.begin(), line.points.end());
    scan.variances.insert(scan.variances.end(), line.variances.begin(), line.variances.end());
    scan.labels.insert(scan.labels.end(), line.labels.begin(), line.labels.end());
  }
  return scan;
}

std::vector<Pose> odometryPoses(const Scene& scene) {
  constexpr double kDegToRad = std::numbers::pi / 180.0;
  const OdometryDrift& drift = scene.odometry;
  const double height = scene.pattern.mount_height;
  std::vector<Pose> result;
  if (scene.poses.empty()) return result;
  Random random(mixSeed(drift.seed, 0x6f646f6dULL, 0));

  const RobotPose& first = scene.poses.front();
  double x = first.x;
  double y = first.y;
  double yaw = first.yaw_deg * kDegToRad;
  result.push_back(robotPose(x, y, yaw, height));
  for (std::size_t i = 1; i < scene.poses.size(); ++i) {
    const RobotPose& from = scene.poses[i - 1];
    const RobotPose& to = scene.poses[i];
    // The true motion in the frame of the previous pose, as the wheels measure it.
    const double from_yaw = from.yaw_deg * kDegToRad;
    const double dx_world = to.x - from.x;
    const double dy_world = to.y - from.y;
    double dx = std::cos(from_yaw) * dx_world + std::sin(from_yaw) * dy_world;
    double dy = -std::sin(from_yaw) * dx_world + std::cos(from_yaw) * dy_world;
    double turn = wrapAngle((to.yaw_deg - from.yaw_deg) * kDegToRad);
    const double distance = std::hypot(dx, dy);
    const double translation_sigma = drift.translation_noise_per_m * distance;
    const double yaw_sigma = std::hypot(drift.yaw_noise_per_rad * std::abs(turn), drift.yaw_noise_per_m * distance);
    dx += translation_sigma * random.gaussian();
    dy += translation_sigma * random.gaussian();
    turn += yaw_sigma * random.gaussian();
    // Integrate the measured motion from the previous odometry pose.
    x += std::cos(yaw) * dx - std::sin(yaw) * dy;
    y += std::sin(yaw) * dx + std::cos(yaw) * dy;
    yaw = wrapAngle(yaw + turn);
    result.push_back(robotPose(x, y, yaw, height));
  }
  return result;
}

std::vector<SimulatedScan> simulate(const Scene& scene, const SimulateOptions& options) {
  std::vector<Pose> odometry;
  if (options.odometry_drift) odometry = odometryPoses(scene);
  std::vector<SimulatedScan> result;
  result.reserve(scene.poses.size());
  for (std::size_t i = 0; i < scene.poses.size(); ++i) {
    SimulatedScan simulated;
    simulated.true_pose = scene.sensorPose(i);
    simulated.odometry_pose = options.odometry_drift ? odometry[i] : simulated.true_pose;
    simulated.scan = simulateScan(scene, simulated.true_pose, i, options);
    result.push_back(std::move(simulated));
    if (options.progress) options.progress(i + 1, scene.poses.size());
  }
  return result;
}

void writeSimulation(const std::filesystem::path& dir, const Scene& scene,
                     const std::vector<SimulatedScan>& scans) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw Error(dir.string() + ": cannot create directory: " + error.message());

  std::vector<io::StampedPose> true_poses;
  std::vector<io::StampedPose> odometry_poses;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "scan_%03zu.xyz", i);
    io::writeXyz(dir / name, scans[i].scan);
    true_poses.push_back({static_cast<double>(i), scans[i].true_pose});
    odometry_poses.push_back({static_cast<double>(i), scans[i].odometry_pose});
  }
  io::writeTumPoses(dir / "poses_true.txt", true_poses);
  io::writeTumPoses(dir / "poses_odom.txt", odometry_poses);

  nlohmann::json planes = nlohmann::json::array();
  for (const GroundTruthPlane& plane : scene.ground_truth) {
    planes.push_back({{"id", plane.id},
                      {"class", std::string(className(plane.surface_class))},
                      {"normal", {plane.normal.x(), plane.normal.y(), plane.normal.z()}},
                      {"d", plane.d},
                      {"name", plane.name}});
  }
  const nlohmann::json document = {{"schema", "mlmap.sim.planes/1"}, {"scene", scene.name}, {"planes", planes}};
  io::writeAtomically(dir / "planes_true.json", [&](std::ostream& out) { out << document.dump(1) << '\n'; });

  io::writeAtomically(dir / "all_world.xyz", [&](std::ostream& out) {
    std::string buffer;
    for (const SimulatedScan& simulated : scans) {
      const Scan& scan = simulated.scan;
      for (std::size_t i = 0; i < scan.size(); ++i) {
        const Point world = scan.worldPoint(i);
        writeNumber(buffer, world.x());
        buffer += ' ';
        writeNumber(buffer, world.y());
        buffer += ' ';
        writeNumber(buffer, world.z());
        buffer += ' ';
        buffer += std::to_string(scan.labels.empty() ? -1 : scan.labels[i]);
        buffer += '\n';
        if (buffer.size() > (1u << 20)) {
          out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
          buffer.clear();
        }
      }
    }
    out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  });
}

}  // namespace mlmap::sim
