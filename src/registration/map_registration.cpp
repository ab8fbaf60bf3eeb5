#include "mlmap/registration/map_registration.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "mlmap/map/ml_map.hpp"
#include "mlmap/map/surface_points.hpp"
#include "mlmap/registration/preprocessing.hpp"
#include "mlmap/registration/wall_yaw.hpp"

namespace mlmap::registration {
namespace {

// m, added to the first gate from the walls' start: what a yaw error of the walls' estimate
// (within 1.3 deg of the truth on the stress benchmark's tune split) moves points at a
// room's 4-5 m reach.
constexpr double kWallYawReach = 0.1;

// Maps are gravity-aligned: merging keeps a transform's yaw and translation only
// (levelledTransform, which keeps the translation: a tilt about the frame's origin). ICP's
// small tilt (noise) comes with a translation that holds the match where the samples are, so
// the tilt is dropped about their centre instead: a room half 5 m from its origin with
// 0.18 deg of tilt was otherwise placed 1-3 cm off (bench/merge_register.py, tune room-1).
Pose levelledAbout(const Pose& pose, const std::vector<Point>& samples) {
  if (samples.empty()) return pose;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Point& point : samples) centre += point;
  centre /= static_cast<double>(samples.size());
  const Eigen::Vector3d forward = pose.linear() * Eigen::Vector3d::UnitX();
  Pose levelled = Pose::Identity();
  levelled.linear() = Eigen::AngleAxisd(std::atan2(forward.y(), forward.x()), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  levelled.translation() = pose * centre - levelled.linear() * centre;
  return levelled;
}

}  // namespace

MapRegistration registerMaps(const Map& base, const Map& other, const Pose& initial_guess,
                             const MapRegistrationConfig& config) {
  const double cell_size = base.config().cell_size;
  // Voxels of a few cells: enough points per voxel for normals, few enough for speed.
  const double voxel_size = std::max(0.1, 2.0 * cell_size);
  const NormalConfig normals{std::max(0.25, 3.0 * cell_size), 6, 0.05};
  // Samples at the mean x, y of each block's points: at cell centres a wall is quantised
  // to the grid, which bounds the match to about half a cell (merged rooms 2-8 cm off at
  // 0.1 m cells, bench/merge_register.py tune split).
  const std::vector<Point> target_samples =
      blockSurfacePoints(base.blocks(), cell_size, SamplePlace::PointMean);
  VoxelHashMap target(voxel_size);
  target.addPoints(target_samples);
  target.estimateNormals(normals);
  const std::vector<Point> other_samples =
      blockSurfacePoints(other.blocks(), other.config().cell_size, SamplePlace::PointMean);
  const std::vector<Point> source = voxelDownSample(other_samples, voxel_size);

  IcpConfig icp;
  icp.initial_max_distance = config.initial_max_distance;
  icp.min_max_distance = std::max(0.1, 2.0 * cell_size);
  icp.min_kernel_scale = std::max(0.01, cell_size / 2.0);
  icp.min_inliers = config.min_inliers;
  // Rooms mapped apart share no frame: the start may be anywhere within the basin (and the
  // retries about it); the answer is verified against the maps' own surface noise.
  BasinConfig basin = config.basin;
  // Block surfaces sit on the cell grid: their noise is at least the quantisation of a
  // cell (uniform over it: cell / √12), whatever the scans' range noise was.
  basin.min_noise = std::max(basin.min_noise, cell_size / std::sqrt(12.0));
  basin.max_start_translation = std::max(basin.max_start_translation, config.max_start_translation);
  basin.levelled = true;  // the result is levelled about its samples (levelledAbout)

  // The walls' dominant directions give the turn between the frames (modulo a quarter
  // turn): a start that needs no yaw retry, where the retries cost a wide ICP run each
  // (a room half from the identity 22 deg off: 5 runs, 8 s). Verified like any other; the
  // guess as given is tried when it is not.
  Pose start = initial_guess;
  VoxelHashMap other_map(voxel_size);
  other_map.addPoints(other_samples);
  other_map.estimateNormals(normals);
  const WallYaw base_walls = wallYaw(target, voxelDownSample(target_samples, voxel_size));
  WallYaw other_walls = wallYaw(other_map, source);
  const Eigen::Vector3d guess_forward = initial_guess.linear() * Eigen::Vector3d::UnitX();
  other_walls.yaw += std::atan2(guess_forward.y(), guess_forward.x());  // as the guess places them
  const double turn = foldedTurn(other_walls, base_walls);
  const bool walls_agree = base_walls.strength >= config.min_wall_strength &&
                           other_walls.strength >= config.min_wall_strength;
  if (walls_agree && std::abs(turn) * 180.0 / std::numbers::pi > basin.max_start_yaw_deg && !source.empty()) {
    // Turned about the other frame's origin, as the retries turn about the sensor: the
    // frames' offset is the start's error, and the farther a map lies from its origin, the
    // more a turn about its centre would move the origin (a lab half 19 deg off: 2 m).
    Pose turned = Pose::Identity();
    turned.linear() = Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    start = initial_guess * turned;
  }
  // From the walls' start the yaw is known to a degree or two, the offset only to the
  // frames' bound: the first gate covers that bound (a 0.5 m gate from a start 0.94 m off
  // slid to a wrong match that explained 37 % of the samples, and an explained result is
  // not retried).
  IcpConfig first = icp;
  if (!start.isApprox(initial_guess)) {
    first.initial_max_distance = std::max(icp.initial_max_distance, basin.max_start_translation + kWallYawReach);
    first.max_fine_distance = std::min(icp.max_fine_distance, icp.initial_max_distance);
  }
  VerifiedIcp verified = alignVerified(source, target, start, first, basin);
  if (!verified.verified && !start.isApprox(initial_guess)) {
    VerifiedIcp as_given = alignVerified(source, target, initial_guess, icp, basin);
    as_given.attempts += verified.attempts;
    if (as_given.verified || !verified.unconstrained) verified = std::move(as_given);
  }
  const IcpResult& result = verified.icp;

  MapRegistration registration;
  registration.other_to_base = levelledAbout(result.pose, source);
  const Eigen::Vector3d up = result.pose.linear() * Eigen::Vector3d::UnitZ();
  registration.tilt_deg = std::acos(std::clamp(up.z(), -1.0, 1.0)) * 180.0 / std::numbers::pi;
  registration.rms_residual = result.rms_residual;
  registration.inliers = result.inliers;
  registration.samples = source.size();
  registration.degenerate = result.degenerate;
  registration.verified = verified.verified;
  registration.explained_share = verified.check.explained_share;
  registration.residual_spread = verified.check.spread;
  registration.noise = verified.noise;
  registration.attempts = verified.attempts;
  const double overlap_distance = config.overlap_distance > 0.0 ? config.overlap_distance
                                                                : std::max(0.1, 2.0 * cell_size);
  std::size_t near = 0;
  const auto count = static_cast<std::int64_t>(source.size());
#pragma omp parallel for reduction(+ : near) schedule(static)
  for (std::int64_t k = 0; k < count; ++k) {
    near += target.nearest(result.pose * source[static_cast<std::size_t>(k)], overlap_distance) ? 1 : 0;
  }
  registration.overlap = source.empty() ? 0.0 : static_cast<double>(near) / static_cast<double>(source.size());

  if (source.empty() || target.empty()) {
    registration.reason = "a map has no blocks";
  } else if (registration.overlap < config.min_overlap) {
    registration.reason = "the maps overlap too little (" + std::to_string(100.0 * registration.overlap) +
                          " % of the other map's surface lies near the base map's)";
  } else if (result.inliers < config.min_inliers) {
    registration.reason = "too few ICP inliers (" + std::to_string(result.inliers) + ")";
  } else if (!verified.verified) {
    registration.reason = verified.reason;
  } else if (registration.tilt_deg > config.max_tilt_deg) {
    // PCL's two room scans, each 1-2° off level, match 1.5° apart: the scans, not the
    // match, need levelling.
    char text[200];
    std::snprintf(text, sizeof text,
                  "the match tilts the other map by %.2f deg: the maps are gravity-aligned (limit %.2f deg); "
                  "scans not level build tilted maps: level them (mlmap calibrate, then --mount)",
                  registration.tilt_deg, config.max_tilt_deg);
    registration.reason = text;
  } else if (!result.converged) {
    registration.reason = "ICP did not converge";
  }
  registration.reliable = registration.reason.empty();
  return registration;
}

}  // namespace mlmap::registration
