#include "mlmap/registration/sequence_registration.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <string>

#include "mlmap/error.hpp"
#include "mlmap/registration/floor_calibration.hpp"
#include "mlmap/registration/preprocessing.hpp"

namespace mlmap::registration {
namespace {

// A pair residual is truncated at this many expected residual spreads (√(target noise² +
// source noise²)).
constexpr double kResidualSigmas = 3.0;
// The graph's poses are kept when the mean residual change is this many standard errors
// below zero and no scan's is this many above (a one-sided test at about 0.1 %).
constexpr double kSignificance = 3.0;

struct ResidualChange {
  double mean_before = 0.0;  // m², over every point of every scan
  double mean_after = 0.0;
  double sigmas = 0.0;       // mean change / its standard error; 0 when nothing changed
  std::size_t scans_worse = 0;
};

// Mean change and its standard error over paired samples.
std::pair<double, double> pairedChange(const std::vector<double>& before, const std::vector<double>& after) {
  double sum = 0.0;
  double sum_sq = 0.0;
  for (std::size_t k = 0; k < before.size(); ++k) {
    const double d = after[k] - before[k];
    sum += d;
    sum_sq += d * d;
  }
  const auto n = static_cast<double>(before.size());
  if (n < 2.0) return {0.0, 0.0};
  const double mean = sum / n;
  const double variance = std::max(0.0, (sum_sq - n * mean * mean) / (n - 1.0));
  return {mean, std::sqrt(variance / n)};
}

double sigmasOf(const std::pair<double, double>& change) {
  if (change.second > 0.0) return change.first / change.second;
  return change.first == 0.0 ? 0.0 : std::copysign(std::numeric_limits<double>::infinity(), change.first);
}

ResidualChange residualChange(const std::vector<std::vector<double>>& before,
                              const std::vector<std::vector<double>>& after) {
  ResidualChange change;
  std::vector<double> all_before;
  std::vector<double> all_after;
  for (std::size_t j = 0; j < before.size(); ++j) {
    all_before.insert(all_before.end(), before[j].begin(), before[j].end());
    all_after.insert(all_after.end(), after[j].begin(), after[j].end());
    if (sigmasOf(pairedChange(before[j], after[j])) > kSignificance) ++change.scans_worse;
  }
  const auto n = static_cast<double>(std::max<std::size_t>(1, all_before.size()));
  for (std::size_t k = 0; k < all_before.size(); ++k) {
    change.mean_before += all_before[k] / n;
    change.mean_after += all_after[k] / n;
  }
  change.sigmas = sigmasOf(pairedChange(all_before, all_after));
  return change;
}

std::vector<Point> transformed(const std::vector<Point>& points, const Pose& pose) {
  std::vector<Point> result;
  result.reserve(points.size());
  for (const Point& point : points) result.push_back(pose * point);
  return result;
}

// Information of an ICP result: its normal equations over the residual variance, without
// the directions ICP flags as degenerate (their eigenvalues are noise, not measurement),
// so odometry alone holds the graph there.
Matrix6d icpInformation(const IcpResult& result, double min_sigma, double min_eigenvalue_ratio,
                        double radius) {
  const double sigma = std::max(result.rms_residual, min_sigma);
  Vector6d scaling;
  scaling << Eigen::Vector3d::Constant(1.0 / radius), Eigen::Vector3d::Ones();
  const Matrix6d scaled = scaling.asDiagonal() * result.hessian * scaling.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(scaled);
  Matrix6d kept = Matrix6d::Zero();
  for (int k = 0; k < 6; ++k) {
    const double eigenvalue = solver.eigenvalues()[k];
    if (eigenvalue < min_eigenvalue_ratio * solver.eigenvalues()[5]) continue;
    kept += eigenvalue * solver.eigenvectors().col(k) * solver.eigenvectors().col(k).transpose();
  }
  const Vector6d unscaling = scaling.cwiseInverse();
  return unscaling.asDiagonal() * kept * unscaling.asDiagonal() / (sigma * sigma);
}

}  // namespace

SequenceRegistration::SequenceRegistration(const SequenceConfig& config)
    : config_(config), map_(config.map_voxel_size, config.max_points_per_voxel) {}

VerifiedIcp SequenceRegistration::addScan(const std::vector<Point>& points, const Pose& world_odometry) {
  // The map's and the pairs' voxel keys reach ±32,768 voxels (OctoMap's): points beyond
  // are never matched, and a cloud in a national grid's coordinates registered nothing.
  // The sequence runs in a frame whose origin the first scan sets (chooseOrigin).
  const double reach = keyReach(std::min(config_.map_voxel_size, config_.pair_voxel_size));
  if (poses_.empty()) origin_ = chooseOrigin(points, world_odometry, reach);
  const Pose odometry = Eigen::Translation3d(-origin_) * world_odometry;
  if (const double farthest = farthestCoordinate(points, odometry); farthest >= reach) {
    char text[160];
    std::snprintf(text, sizeof(text), "scan %zu lies %.0f m from the first, beyond the %.0f m",
                  poses_.size() + 1, farthest, reach);
    throw Error(std::string(text) + " the registration's voxel keys reach from where the first scan lies");
  }
  // The map and the local maps take a finer sample than the ICP source: their normals
  // need neighbours.
  const std::vector<Point> dense =
      voxelDownSample(points, config_.map_voxel_size / 2.0, config_.min_range, config_.max_range);
  std::vector<Point> source = voxelDownSample(points, config_.source_voxel_size, config_.min_range, config_.max_range);

  VerifiedIcp result;
  Pose pose = odometry;
  bool levelled = false;
  if (poses_.empty()) {
    result.icp.pose = result.start = result.kept_start = pose;
    result.icp.converged = true;
    result.icp.unreliable = false;
    result.icp.source_points = source.size();
    result.verified = true;
  } else {
    const Pose guess = poses_.back() * (odometry_.back().inverse() * odometry);
    result = alignVerified(source, map_, guess, config_.icp, config_.basin);
    pose = result.icp.pose;
    // Where the geometry leaves a direction free, the scan's own floor holds its tilt and
    // height (a room whose scans share little floor: ICP keeps a weak tilt where the odometry
    // put it, up to a degree off per step).
    if (result.unconstrained && reference_floor_) {
      if (const std::optional<Floor> floor = floorOf(source)) {
        const Pose on_floor = levelledOnFloor(pose, *floor, source);
        levelled = !on_floor.isApprox(pose);
        pose = result.icp.pose = on_floor;
      } else if (const std::optional<double> shift = shiftOntoReferenceFloor(pose, source, result.check.sigma)) {
        pose.translation() += *shift * reference_floor_->up;
        result.icp.pose = pose;
        levelled = true;
      }
    }
  }
  if (config_.level_from_floor && !reference_floor_) {
    if (const std::optional<Floor> floor = floorOf(source)) {
      reference_floor_ = Floor{pose.linear() * floor->up, 0.0};
      reference_floor_->height = reference_floor_->up.dot(pose * Eigen::Vector3d(-floor->height * floor->up));
    }
  }
  map_.addPoints(transformed(dense, pose));
  map_.estimateNormals(config_.normals);
  dense_.push_back(std::move(dense));
  // The source sample down-sampled again (cheaper than the whole scan, the same voxels' points).
  sources_.push_back(voxelDownSample(source, config_.pair_voxel_size, 0.0, std::numeric_limits<double>::infinity()));
  odometry_.push_back(odometry);
  poses_.push_back(pose);
  chain_.push_back(pose);
  levelled_.push_back(levelled);
  for (Pose* world : {&result.start, &result.kept_start, &result.icp.pose}) world->pretranslate(origin_);
  return result;
}

std::vector<Pose> SequenceRegistration::poses() const {
  std::vector<Pose> world = poses_;
  for (Pose& pose : world) pose.pretranslate(origin_);
  return world;
}

std::optional<SequenceRegistration::Floor> SequenceRegistration::floorOf(const std::vector<Point>& source) const {
  if (!config_.level_from_floor) return std::nullopt;
  try {
    const FloorCalibration floor = calibrateFromFloor(source);
    if (floor.floor_points < config_.min_floor_points) return std::nullopt;
    return Floor{floor.floor_normal, floor.floor_distance};
  } catch (const Error&) {
    return std::nullopt;  // no floor in view
  }
}

Pose SequenceRegistration::levelledOnFloor(const Pose& pose, const Floor& floor, const std::vector<Point>& source) const {
  const Eigen::Quaterniond turn = Eigen::Quaterniond::FromTwoVectors(pose.linear() * floor.up, reference_floor_->up);
  if (Eigen::AngleAxisd(turn).angle() > config_.max_level_turn_deg * std::numbers::pi / 180.0) return pose;
  // Turned about the scan's centre, where ICP matched it (as merge levels a map about its samples).
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Point& point : source) centre += point;
  centre = pose * (centre / static_cast<double>(std::max<std::size_t>(1, source.size())));
  Pose levelled = pose;
  levelled.linear() = turn.toRotationMatrix() * pose.linear();
  levelled.translation() = centre + turn.toRotationMatrix() * (pose.translation() - centre);
  // ... and set on the reference floor's height, unless it stands on another level.
  const double height = reference_floor_->up.dot(levelled * Eigen::Vector3d(-floor.height * floor.up));
  const double shift = reference_floor_->height - height;
  if (std::abs(shift) <= config_.max_level_shift) levelled.translation() += shift * reference_floor_->up;
  return levelled;
}

// Too little floor of its own for a tilt (floorOf), a scan may still show a strip of floor
// by the reference floor's plane: its height along it. The stress benchmark's fresh room-22:
// scan 1 faces a box 1 m off and holds 156 floor points of its 0.05 m sample (min_floor_points
// 500), and ICP left its height where the odometry put it, up to 10.6 cm low. Its points within
// twice max_level_shift of the plane (the floor, the foot of the walls and boxes) are searched
// for the densest slab 4 σ thick (σ the expected residual): the floor's points there, the
// others spread over the band. Returns the shift along `up` that puts that slab's median on
// the plane, where the slab holds at least min_reference_floor_points and the shift is within
// max_level_shift (more: another level, a low table top).
std::optional<double> SequenceRegistration::shiftOntoReferenceFloor(const Pose& pose, const std::vector<Point>& source,
                                                                    double sigma) const {
  if (!reference_floor_ || config_.min_reference_floor_points == 0) return std::nullopt;
  const double band = 2.0 * config_.max_level_shift;
  // At least 5 mm of σ (a slab 2 cm thick): a guard where the expected residual reads very
  // small, not a figure measured on any data (it is at least 2.8 mm, √2 × BasinConfig::min_noise).
  constexpr double kMinSlabSigma = 0.005;
  const double half_slab = 2.0 * std::max(sigma, kMinSlabSigma);
  std::vector<double> heights;  // above the reference floor, m
  for (const Point& point : source) {
    const double height = reference_floor_->up.dot(pose * point) - reference_floor_->height;
    if (std::abs(height) <= band) heights.push_back(height);
  }
  if (heights.size() < config_.min_reference_floor_points) return std::nullopt;
  std::sort(heights.begin(), heights.end());
  std::size_t best_first = 0, best_count = 0;
  for (std::size_t first = 0, last = 0; first < heights.size(); ++first) {
    while (last < heights.size() && heights[last] <= heights[first] + 2.0 * half_slab) ++last;
    if (last - first > best_count) {
      best_count = last - first;
      best_first = first;
    }
  }
  if (best_count < config_.min_reference_floor_points) return std::nullopt;
  const double median = heights[best_first + best_count / 2];
  if (std::abs(median) > config_.max_level_shift) return std::nullopt;
  return -median;
}

RefinementResult SequenceRegistration::refine() {
  RefinementResult result;
  if (poses_.size() < 2) return result;
  IcpConfig pair_config = config_.icp;
  pair_config.initial_max_distance = std::max(config_.icp.min_max_distance, 0.25);
  // The poses are already registered: a pair is checked, not searched for again.
  BasinConfig pair_basin = config_.basin;
  pair_basin.retry = false;
  pair_basin.check_turns = false;  // each scan's pose was checked against its rivals when it was added
  pair_basin.max_start_translation = 0.0;
  pair_basin.max_start_yaw_deg = 0.0;
  // Each scan alone in its sensor frame: the targets of the pairwise ICP, with its noise.
  // Each scan's noise, measured once here rather than in every pair, on its local map; as a
  // source it counts the same (measured on their own, the simulated lab's down-sampled
  // scans show 0.40-0.55 cm against 0.36-0.45 cm for the map, and cost a voxel hash each).
  std::vector<VoxelHashMap> locals;
  std::vector<double> noise;
  for (const std::vector<Point>& dense : dense_) {
    locals.emplace_back(config_.map_voxel_size, config_.max_points_per_voxel);
    locals.back().addPoints(dense);
    locals.back().estimateNormals(config_.normals);
    noise.push_back(config_.basin.noise > 0.0 ? config_.basin.noise
                                              : std::max(config_.basin.min_noise, locals.back().surfaceNoise()));
  }
  const std::vector<double>& source_noise =
      config_.basin.source_noise > 0.0 ? std::vector<double>(noise.size(), config_.basin.source_noise) : noise;
  // Each scan's sample as a source, its normals and noise at the locals' voxel size: the same
  // in every pair it is the source of (cloudSurfaces), measured before its first pair.
  std::vector<std::optional<CloudSurfaces>> source_surfaces(sources_.size());
  for (int round = 0; round < config_.refinement_rounds; ++round) {
    std::vector<PoseGraphEdge> edges;
    for (std::size_t i = 0; i + 1 < poses_.size(); ++i) {
      PoseGraphEdge edge;
      edge.from = i;
      edge.to = i + 1;
      edge.measurement = chain_[i].inverse() * chain_[i + 1];
      edge.pivot = edge.measurement.translation();
      const double rotation_sq = config_.chain_sigma_rotation * config_.chain_sigma_rotation;
      const double translation_sq = config_.chain_sigma_translation * config_.chain_sigma_translation;
      edge.information.diagonal() << Eigen::Vector3d::Constant(1.0 / rotation_sq),
          Eigen::Vector3d::Constant(1.0 / translation_sq);
      edges.push_back(edge);
    }
    // Candidate pairs (consecutive or not: a scan that sees an earlier one's space again
    // closes a loop), then pairwise ICP in parallel (each pair writes only its own slot).
    std::vector<std::pair<std::size_t, std::size_t>> pairs;
    for (std::size_t i = 0; i < poses_.size(); ++i) {
      for (std::size_t j = i + 1; j < poses_.size(); ++j) {
        if ((poses_[i].translation() - poses_[j].translation()).norm() <= config_.max_pair_distance) {
          pairs.emplace_back(i, j);
        }
      }
    }
    // The scans each scan's residuals are measured against: every candidate partner.
    std::vector<std::vector<std::size_t>> neighbours(poses_.size());
    for (const auto& [i, j] : pairs) {
      neighbours[i].push_back(j);
      neighbours[j].push_back(i);
    }
    for (const auto& [i, j] : pairs) {
      if (!source_surfaces[j]) source_surfaces[j] = cloudSurfaces(sources_[j], config_.map_voxel_size);
    }
    std::vector<VerifiedIcp> pair_results(pairs.size());
    BasinConfig basin = pair_basin;
#pragma omp parallel for schedule(dynamic, 1) firstprivate(basin)
    for (long p = 0; p < static_cast<long>(pairs.size()); ++p) {
      const auto [i, j] = pairs[static_cast<std::size_t>(p)];
      basin.noise = noise[i];
      basin.source_noise = source_noise[j];
      pair_results[static_cast<std::size_t>(p)] =
          alignVerified(sources_[j], *source_surfaces[j], locals[i], poses_[i].inverse() * poses_[j], pair_config, basin);
    }
    result.pair_edges = 0;
    result.loop_edges = 0;
    result.rejected_pairs = 0;
    result.unconstrained_pairs = 0;
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      const IcpResult& icp = pair_results[p].icp;
      const double overlap =
          icp.source_points > 0 ? static_cast<double>(icp.inliers) / static_cast<double>(icp.source_points) : 0.0;
      // Verified pairs only: an unconstrained pair's free direction is not the eigenvector
      // of its normal equations (leaning normals give a corridor's axis spurious
      // information), so dropping its weakest eigenvalues still left the graph a wrong pull
      // along the axis (the long corridor 24.2 -> 27.2 cm ATE, register_ate.py --max-yaw 30).
      if (!pair_results[p].verified || !icp.converged || icp.inliers < config_.icp.min_inliers ||
          overlap < config_.min_overlap) {
        ++result.rejected_pairs;
        if (pair_results[p].unconstrained) ++result.unconstrained_pairs;
        continue;
      }
      PoseGraphEdge edge;
      edge.from = pairs[p].first;
      edge.to = pairs[p].second;
      edge.measurement = icp.pose;
      edge.pivot = icp.pivot;
      edge.information = icpInformation(icp, config_.icp.min_kernel_scale, config_.icp.min_eigenvalue_ratio,
                                        icp.radius);
      edges.push_back(edge);
      ++result.pair_edges;
      if (edge.to != edge.from + 1) ++result.loop_edges;
    }
    if (result.pair_edges == 0) break;  // the graph would hold the chain: the poses as they are
    std::vector<Pose> candidate = poses_;
    result.graph = optimizePoseGraph(candidate, edges);
    // Kept only where it lowers the residuals of every scan against the others (all scans
    // near it, not only the verified pairs: a pair's own residual does not follow a scan
    // that slides against the rest). Paired per point: the same points before and after.
    const std::vector<std::vector<double>> before =
        scanResiduals(poses_, neighbours, locals, noise, source_noise);
    const std::vector<std::vector<double>> after =
        scanResiduals(candidate, neighbours, locals, noise, source_noise);
    const ResidualChange change = residualChange(before, after);
    if (round == 0) result.residual_before = change.mean_before;
    result.residual_change_sigmas = change.sigmas;
    result.scans_worse = change.scans_worse;
    if (change.sigmas < -kSignificance && change.scans_worse == 0) {
      poses_ = std::move(candidate);
      result.residual_after = change.mean_after;
      ++result.rounds_applied;
    } else {
      result.residual_after = change.mean_before;
      break;
    }
  }
  if (result.rounds_applied == 0) result.residual_after = result.residual_before;
  return result;
}

std::vector<std::vector<double>> SequenceRegistration::scanResiduals(
    const std::vector<Pose>& poses, const std::vector<std::vector<std::size_t>>& neighbours,
    const std::vector<VoxelHashMap>& locals, const std::vector<double>& noise,
    const std::vector<double>& source_noise) const {
  std::vector<std::vector<double>> residuals(dense_.size());
  const double target_noise = noise.empty() ? 0.0 : *std::max_element(noise.begin(), noise.end());
#pragma omp parallel for schedule(dynamic, 1)
  for (long jj = 0; jj < static_cast<long>(dense_.size()); ++jj) {
    const auto j = static_cast<std::size_t>(jj);
    // Residuals beyond a few σ are points the other scans do not see: they count as that
    // bound, so a pose that moves a point out of overlap gains nothing.
    const double bound = kResidualSigmas * std::hypot(target_noise, source_noise[j]);
    std::vector<double>& out = residuals[j];
    out.assign(dense_[j].size(), bound * bound);
    for (const std::size_t i : neighbours[j]) {
      const Pose relative = poses[i].inverse() * poses[j];
      for (std::size_t k = 0; k < dense_[j].size(); ++k) {
        const Point moved = relative * dense_[j][k];
        const std::optional<Neighbour> neighbour = locals[i].nearest(moved, config_.icp.min_max_distance);
        if (!neighbour || neighbour->normal.isZero()) continue;
        const double r = neighbour->normal.dot(moved - neighbour->point);
        out[k] = std::min(out[k], r * r);
      }
    }
  }
  return residuals;
}

}  // namespace mlmap::registration
