#include "mlmap/driver/acquisition.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <tuple>

#include "mlmap/driver/tilt_sync.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/pcd.hpp"

namespace mlmap::driver {
namespace {

constexpr double kDegree = 3.14159265358979323846 / 180.0;

int toPositions(double degrees, const PtuAxisInfo& axis) {
  return static_cast<int>(std::lround(degrees / axis.degreesPerPosition()));
}

// The measurement of one cluster is timed at its middle step (the emulator casts it there).
double clusterStep(const ScipScan& scan, std::size_t index) {
  const double first = scan.start_step + static_cast<double>(index) * scan.cluster;
  const double last = std::min<double>(first + scan.cluster - 1, scan.end_step);
  return 0.5 * (first + last);
}

}  // namespace

double rangeVariance(double range) { return range <= 10.0 ? 0.03 * 0.03 : 0.05 * 0.05; }

namespace {

SweepResult runSweep(ScipClient& laser, PtuClient& ptu, const SweepOptions& options,
                     const Pose& odometry_pose, const std::function<void(std::size_t lines)>& progress) {
  if (!(options.rho_deg > 0.0) || options.cluster < 1 || options.cluster > 99 ||
      options.time_samples < 1 || options.timeout_ms < 1) {
    throw Error("scan: bad sweep options (rho > 0, cluster 1-99, time samples >= 1)");
  }
  const auto timeout = std::chrono::milliseconds(options.timeout_ms);
  SweepResult result;

  // Laser: stop whatever runs, read its parameters (never assumed), switch it on.
  laser.connect();  // SCIP 2.0 (a URG-04LX may start in SCIP 1.1), nothing running
  laser.versionInfo();
  result.laser = laser.parameters();
  laser.status();
  laser.laserOn();
  const ScipParameters& parameters = result.laser;
  const double revolution_hz = parameters.revolutionHz();

  // Pan-tilt: resolution and limits from the unit, then to (α, γ_s).
  ptu.initialise();
  const PtuAxisInfo& pan_axis = ptu.axis(PtuAxis::Pan);
  const PtuAxisInfo& tilt_axis = ptu.axis(PtuAxis::Tilt);
  const int pan_position = toPositions(options.pan_deg, pan_axis);
  const int start_position = toPositions(options.tilt_start_deg, tilt_axis);
  const int end_position = toPositions(options.tilt_end_deg, tilt_axis);
  for (const auto& [degrees, position, info, name] :
       {std::tuple{options.pan_deg, pan_position, &pan_axis, "pan"},
        std::tuple{options.tilt_start_deg, start_position, &tilt_axis, "tilt start"},
        std::tuple{options.tilt_end_deg, end_position, &tilt_axis, "tilt end"}}) {
    if (position < info->min_position || position > info->max_position) {
      char range[96];
      std::snprintf(range, sizeof(range), "[%.2f, %.2f] deg",
                    info->min_position * info->degreesPerPosition(),
                    info->max_position * info->degreesPerPosition());
      throw PtuError(PtuError::Kind::Refused, ptu.transport().name() + ": " + name + " " +
                                                  std::to_string(degrees) + " deg is outside the unit's limits " + range);
    }
  }
  const int speed = std::max(1, toPositions(tiltSpeedDegS(options.rho_deg, revolution_hz), tilt_axis));  // eq. 3
  const int base = std::max(0, toPositions(options.base_speed_deg_s, tilt_axis));
  const int acceleration = std::max(1, toPositions(options.acceleration_deg_s2, tilt_axis));
  ptu.setSpeed(PtuAxis::Tilt, speed);
  ptu.setBaseSpeed(PtuAxis::Tilt, std::min(base, speed));
  ptu.setAcceleration(PtuAxis::Tilt, acceleration);
  // Clock samples before and after positioning, then after the sweep: the groups span
  // seconds, so the fit sees the drift (and an emulator's time scale).
  auto samples = laser.timeSamples(options.time_samples);
  ptu.setPosition(PtuAxis::Pan, pan_position);
  ptu.setPosition(PtuAxis::Tilt, start_position);
  const double positioning_s =
      std::abs(static_cast<double>(start_position)) * 2.0 / speed + 2.0 + 10.0;
  ptu.await(std::chrono::milliseconds(static_cast<int>(positioning_s * 1000.0)) + timeout);
  const auto positioned = laser.timeSamples(options.time_samples);
  samples.insert(samples.end(), positioned.begin(), positioned.end());
  const ClockModel early_clock = fitClock(samples);

  TrapezoidalProfile profile;
  profile.start_deg = start_position * tilt_axis.degreesPerPosition();
  profile.end_deg = end_position * tilt_axis.degreesPerPosition();
  profile.speed_deg_s = speed * tilt_axis.degreesPerPosition();
  profile.base_speed_deg_s = std::min(base, speed) * tilt_axis.degreesPerPosition();
  profile.acceleration_deg_s2 = acceleration * tilt_axis.degreesPerPosition();
  result.sweep_duration_s = profile.duration();

  if (options.intensity) {
    laser.startIntensityScans(parameters.first_step, parameters.last_step, options.cluster, 0);
  } else {
    laser.startScans(parameters.first_step, parameters.last_step, options.cluster, true, 0);
  }
  std::vector<ScipScan> lines;
  lines.push_back(laser.nextScan());  // the stream runs before the tilt starts
  ptu.setPosition(PtuAxis::Tilt, end_position);
  const double t0_host = 0.5 * (ptu.lastSent() + ptu.lastReplied());
  const double tp_half_round_trip = 0.5 * (ptu.lastReplied() - ptu.lastSent());
  ptu.startAwait();
  // Scans until the PTU reports the move done and the laser has a scan that started
  // after the sweep's end (with a revolution to spare); frames can lag behind the PTU.
  const double sweep_end_device =
      early_clock.toDevice(t0_host) + result.sweep_duration_s + 1.0 / revolution_hz;
  const std::size_t max_lines =
      static_cast<std::size_t>((result.sweep_duration_s + 2.0) * revolution_hz * 4.0) + 100;
  bool ptu_done = false;
  while (!ptu_done || static_cast<double>(lines.back().timestamp_ms) * 1e-3 < sweep_end_device) {
    lines.push_back(laser.nextScan());
    if (progress) progress(lines.size());
    if (!ptu_done) ptu_done = ptu.awaitDone(std::chrono::milliseconds(0));
    if (lines.size() > max_lines) {
      throw Error(ptu.transport().name() + ": tilt sweep did not finish (" +
                  (ptu_done ? "laser clock never passed the sweep's end" : "no answer to A") +
                  " after " + std::to_string(lines.size()) + " laser scans)");
    }
  }
  laser.stop();
  const auto after = laser.timeSamples(options.time_samples);
  samples.insert(samples.end(), after.begin(), after.end());
  result.clock = fitClock(samples);
  result.tilt_start_device_s = result.clock.toDevice(t0_host);  // t_0 of eq. 2
  // Where in its round trip the PTU started is unknown; TM values are whole milliseconds.
  result.sync_uncertainty_s =
      tp_half_round_trip * result.clock.rate + result.clock.max_residual_s + 1e-3;
  result.dropped_frames = laser.counters().dropped_frames;

  const double pan = pan_position * pan_axis.degreesPerPosition() * kDegree;
  Scan& scan = result.scan;
  scan.pose = odometry_pose;
  const double min_range = parameters.min_range_mm * 1e-3, max_range = parameters.max_range_mm * 1e-3;
  const double revolution_ms = 1000.0 / revolution_hz;
  for (std::size_t k = 1; k < lines.size(); ++k) {
    const double gap_ms = static_cast<double>(lines[k].timestamp_ms - lines[k - 1].timestamp_ms);
    if (gap_ms > 1.5 * revolution_ms) {
      result.missed_revolutions += static_cast<std::size_t>(std::lround(gap_ms / revolution_ms)) - 1;
    }
  }
  for (const ScipScan& line : lines) {
    const double scan_start = static_cast<double>(line.timestamp_ms) * 1e-3;
    bool used = false;
    for (std::size_t i = 0; i < line.ranges_mm.size(); ++i) {
      const double step = clusterStep(line, i);
      const double t = stepTime(scan_start, step - parameters.first_step, revolution_hz,
                                parameters.steps_per_revolution);  // eq. 1
      const double l = t - result.tilt_start_device_s;             // eq. 2
      if (l < 0.0 || l > result.sweep_duration_s) continue;
      used = true;
      const double range = line.ranges_mm[i] * 1e-3;
      if (range < min_range || range > max_range) continue;  // error codes, out of range
      const double tilt = profile.angleAt(l) * kDegree;
      scan.points.push_back(beamPoint(options.mount, pan, tilt, parameters.stepAngle(step), range));  // eq. 4
      scan.variances.push_back(rangeVariance(range));
      if (i < line.intensities.size()) result.intensities.push_back(line.intensities[i]);
    }
    if (used) ++result.scan_lines;
  }
  if (result.scan_lines == 0) {
    throw Error(laser.transport().name() + ": no laser scan fell inside the " +
                std::to_string(result.sweep_duration_s) + " s tilt sweep (" +
                std::to_string(result.missed_revolutions) + " revolutions missing from the stream)");
  }
  return result;
}

}  // namespace

SweepResult acquireScan(ScipClient& laser, PtuClient& ptu, const SweepOptions& options,
                        const Pose& odometry_pose,
                        const std::function<void(std::size_t lines)>& progress) {
  try {
    return runSweep(laser, ptu, options, odometry_pose, progress);
  } catch (const Error&) {
    try {
      laser.stop();  // leave the laser quiet where it still answers
    } catch (const Error&) {
    }
    throw;
  }
}

std::size_t nextScanIndex(const std::filesystem::path& dir) {
  for (std::size_t index = 0;; ++index) {
    char name[32];
    std::snprintf(name, sizeof(name), "scan_%03zu.pcd", index);
    if (!std::filesystem::exists(dir / name)) return index;
  }
}

std::filesystem::path saveScan(const std::filesystem::path& dir, std::size_t index, const Scan& scan) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw Error(dir.string() + ": cannot create directory: " + error.message());
  char name[32];
  std::snprintf(name, sizeof(name), "scan_%03zu.pcd", index);
  io::writePcd(dir / name, scan, io::PcdEncoding::Binary);
  return dir / name;
}

std::string sweepToJson(const SweepOptions& options, const Pose& odometry_pose) {
  nlohmann::json json;
  json["pan_deg"] = options.pan_deg;
  json["tilt_start_deg"] = options.tilt_start_deg;
  json["tilt_end_deg"] = options.tilt_end_deg;
  json["rho_deg"] = options.rho_deg;
  json["base_speed_deg_s"] = options.base_speed_deg_s;
  json["acceleration_deg_s2"] = options.acceleration_deg_s2;
  json["cluster"] = options.cluster;
  json["time_samples"] = options.time_samples;
  json["timeout_ms"] = options.timeout_ms;
  json["intensity"] = options.intensity;
  json["mount"] = {{"tilt_axis_height", options.mount.tilt_axis_height},
                   {"laser_offset", {options.mount.laser_offset.x(), options.mount.laser_offset.y(),
                                     options.mount.laser_offset.z()}}};
  std::vector<double> matrix;
  for (int row = 0; row < 4; ++row) {
    for (int column = 0; column < 4; ++column) matrix.push_back(odometry_pose.matrix()(row, column));
  }
  json["odometry_pose"] = matrix;
  return json.dump();
}

namespace {

// An integer that fits `Integer`: json's own get<int>() of 1e300 or -1 into an unsigned
// would be undefined behaviour or wrap.
template <typename Integer>
Integer integerField(const nlohmann::json& json, const char* key, const std::string& source_name) {
  const nlohmann::json& value = json.at(key);
  constexpr auto kMin = static_cast<std::int64_t>(std::numeric_limits<Integer>::min());
  constexpr auto kMax = static_cast<std::uint64_t>(std::numeric_limits<Integer>::max());
  static_assert(kMax <= static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()));
  const bool fits = value.is_number_unsigned()  ? value.get<std::uint64_t>() <= kMax
                    : value.is_number_integer() ? value.get<std::int64_t>() >= kMin &&
                                                      value.get<std::int64_t>() <= static_cast<std::int64_t>(kMax)
                                                : false;
  if (!fits) {
    throw Error(source_name + ": bad sweep metadata: " + key + " is not an integer from " +
                std::to_string(kMin) + " to " + std::to_string(kMax));
  }
  return static_cast<Integer>(value.get<std::int64_t>());
}

}  // namespace

void sweepFromJson(const std::string& json_text, const std::string& source_name,
                   SweepOptions& options, Pose& odometry_pose) {
  try {
    const auto json = nlohmann::json::parse(json_text);
    options.pan_deg = json.at("pan_deg").get<double>();
    options.tilt_start_deg = json.at("tilt_start_deg").get<double>();
    options.tilt_end_deg = json.at("tilt_end_deg").get<double>();
    options.rho_deg = json.at("rho_deg").get<double>();
    options.base_speed_deg_s = json.at("base_speed_deg_s").get<double>();
    options.acceleration_deg_s2 = json.at("acceleration_deg_s2").get<double>();
    options.cluster = integerField<std::uint32_t>(json, "cluster", source_name);
    options.time_samples = integerField<int>(json, "time_samples", source_name);
    options.timeout_ms = integerField<int>(json, "timeout_ms", source_name);
    // Logs from before ME was read have no "intensity": they streamed MD.
    options.intensity = json.contains("intensity") && json.at("intensity").get<bool>();
    options.mount = parseMountConfig(json.at("mount").dump(), source_name + ": mount");
    const auto matrix = json.at("odometry_pose").get<std::vector<double>>();
    if (matrix.size() != 16) throw Error(source_name + ": odometry_pose: expected 16 numbers");
    Eigen::Matrix4d pose;
    for (int i = 0; i < 16; ++i) pose(i / 4, i % 4) = matrix[static_cast<std::size_t>(i)];
    odometry_pose.matrix() = pose;
  } catch (const nlohmann::json::exception& error) {
    throw Error(source_name + ": bad sweep metadata: " + error.what());
  }
}

}  // namespace mlmap::driver
