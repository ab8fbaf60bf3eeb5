// The ICP loop as a few named steps (transform + associate + build the normal equations in
// one pass, adapt the gate, solve, update, converged?), like KISS-ICP's Registration.cpp,
// in two stages: a sparse coarse stage at the wide initial gate, then every point.
#include "mlmap/registration/icp.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace mlmap::registration {
namespace {

constexpr double kMadToSigma = 1.4826;  // MAD -> standard deviation of a Gaussian
constexpr std::size_t kBlockSize = 512; // points per partial sum of the reduction
// Fewer searches in a pass: one thread. The coarse stage's passes (~1500 searches at a
// 0.5-1.5 m gate, 1.3-2.4 us each: 2-3.5 ms) are above it: on 2 threads shared with another
// job's (load 2.8-3.9 on 2 CPUs) the stress benchmark's held-out split took 10 % less time per
// run from large starts (median 0.115 -> 0.103 s, 4 alternating rounds; small 0.052 -> 0.050 s)
// than with the coarse stage on one thread (threshold 4000), the same results to the bit.
constexpr std::size_t kParallelSearches = 1000;
// The coarse stage: about this many source points, at most this many iterations, until
// points move less than this fraction of the smallest gate in one iteration; its kernel
// scale is the gate over this divisor, and directions whose eigenvalue ratio is below this
// factor times the degeneracy threshold stay put.
constexpr std::size_t kCoarsePoints = 1500;
constexpr int kMaxCoarseIterations = 20;
constexpr double kCoarseSettledMotion = 0.05;
constexpr double kCoarseKernelDivisor = 6.0;
constexpr double kCoarseEigenvalueFactor = 2.0;
// The middle stage: after a coarse stage that ended with the gate still wide (its steps
// settled, but 3 x the residuals' spread is decimetres: a far start's mismatches), the fine
// stage's first passes search at that gate, tens of voxels per search for every point (10-23
// ms a pass on the stress benchmark's scans of 23,000 points, a quarter of the run's time
// from large starts). Every so many points (about kMiddlePoints) steer instead until the gate
// has closed to kDenseGateFactor x its floor, the pose stops moving (as the coarse stage) or
// kMaxCoarseIterations passes went by; then every point refines, and only then may the run
// reuse matches or converge. Stress benchmark, tuned on the tune split (one thread, CPU over
// all 126 starts, 2 rounds): 26.8 -> 24.0 s; 1.5 x or 1.2 x the floor and 2000 points within
// 2 % of that, 6000 points 2.5 % slower. The same successes and verdicts, start by start, on
// every split (report: 28.7 -> 25.7 s, large starts' median -14 %). Sequences with drifting
// odometry enter it too (register_ate.py, 384): 79 ATEs moved, 32 down and 34 up by at most
// 0.3 / 0.6 cm, 371 -> 369 within 1 cm (two fresh corridors along their free axis, to 1.01 and
// 1.07 cm). Session 45's middle stage, at every gate, lost 6 and failed the corridor tests.
constexpr std::size_t kMiddlePoints = 3000;
constexpr double kDenseGateFactor = 2.0;
// The coarse stage converges linearly: at the 0.5 m gate its steps shrink by 5-10 % an
// iteration along a nearly constant direction (the lab from 8-10 deg off: 1-3 cm a step for
// 20 iterations, ending at the iteration cap). Two successive steps within this angle of each
// other (cos 0.9: 26 deg), the second shorter, are read as a geometric series, and its
// remainder r/(1 - r) times the last step is taken at once (Aitken's extrapolation), moving
// points at most this fraction of the gate: the matches that measured the step lie within the
// gate. Stress benchmark, tune split (7 scenes, 84 starts), CPU time on one thread, large starts
// 7.4 -> 5.6 s (lab -42 %, long corridor -28 %, room 3 -26 %, symmetric -20 %, rooms 1-2
// -13-15 %, shipped corridor the same), small starts -20 % in the lab and the long corridor,
// the same elsewhere; the same successes and median errors. Cosines 0.8-0.95 and fractions
// 0.25-0.5 gave the same within 3 % (a first version, which also extrapolated 2-5 mm steps);
// a fraction of 1.0 was 13 % slower, and extrapolating the fine stage's steps too saved nothing.
constexpr double kExtrapolateCosine = 0.9;
constexpr double kExtrapolateGateShare = 0.5;
// Correspondences are kept, not searched again, after an iteration that moved points less
// than this fraction of the smallest kernel scale (the range noise).
constexpr double kReuseMotion = 0.2;
// Points that found no partner within the gate are not searched again while points have
// moved less than this fraction of the gate since (the gate never widens).
constexpr double kMissMotion = 0.25;

// How a pass finds its correspondences.
enum class Search {
  All,         // every sampled point searches the map
  SkipMisses,  // ... except those that found nothing at the last search
  Reuse,       // no search: the last matches stand, residuals are evaluated again
};

struct LinearSystem {
  Matrix6d hessian = Matrix6d::Zero();
  Vector6d gradient = Vector6d::Zero();
  LinearSystem& operator+=(const LinearSystem& other) {
    hessian += other.hessian;
    gradient += other.gradient;
    return *this;
  }
};

// What one pass over the source yields: the normal equations and, per point, its match
// and the magnitude of its residual (negative: no correspondence), from which the gate
// adapts; whether its last search found nothing.
struct Pass {
  LinearSystem system;
  std::vector<double> residuals;
  std::vector<Neighbour> matches;
  std::vector<char> missed;
  // Where a point stood and how far its search reached when it last found nothing: no map
  // point lies within that reach of that place.
  std::vector<Point> missed_at;
  std::vector<double> missed_reach;
  std::vector<char> has_match;  // matches[i] holds a map point found for point i in this run
};

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// Every how many points a sample of about `sample` points of `points` takes (at least 1).
long sampleStride(std::size_t points, std::size_t sample) {
  return std::max(1L, static_cast<long>(points / sample));
}

// Adds one correspondence's Geman–McClure weighted term to Σ w·JᵀJ and Σ w·Jᵀr, for the
// increment (ω about `pivot`, v); returns the residual's magnitude.
double addTerm(const Point& source, const Neighbour& target, IcpMetric metric, double scale_sq,
               const Eigen::Vector3d& pivot, LinearSystem& system) {
  const Eigen::Vector3d arm = source - pivot;
  if (metric == IcpMetric::PointToPlane) {
    const double residual = target.normal.dot(source - target.point);
    Vector6d jacobian;
    jacobian << arm.cross(target.normal), target.normal;
    const double root = scale_sq / (scale_sq + residual * residual);
    const double weight = root * root;
    system.hessian.noalias() += weight * jacobian * jacobian.transpose();
    system.gradient.noalias() += weight * residual * jacobian;
    return std::abs(residual);
  }
  const Eigen::Vector3d residual = source - target.point;
  Eigen::Matrix<double, 3, 6> jacobian;
  jacobian << -skew(arm), Eigen::Matrix3d::Identity();
  const double root = scale_sq / (scale_sq + residual.squaredNorm());
  const double weight = root * root;
  system.hessian.noalias() += weight * jacobian.transpose() * jacobian;
  system.gradient.noalias() += weight * jacobian.transpose() * residual;
  return residual.norm();
}

// Transform, associate and build the normal equations in one parallel pass over every
// `stride`-th source point (one fork-join per iteration: on a busy machine each join waits
// for the slowest thread's time slice). With point-to-plane, map points without a normal
// give no correspondence. Search::Reuse keeps the last matches: once the pose moves by a
// millimetre per iteration the nearest map point, and surely its voxel's plane, stays.
// Partial sums over fixed blocks, added in block order: the same result at any thread count.
void associateAndBuild(const std::vector<Point>& source, const VoxelHashMap& target, const Pose& pose,
                       double gate, IcpMetric metric, long stride, Search search, double scale,
                       const Eigen::Vector3d& pivot, Pass& pass) {
  const double scale_sq = scale * scale;
  const std::size_t blocks = (source.size() + kBlockSize - 1) / kBlockSize;
  std::vector<LinearSystem> partial(blocks);
  pass.matches.resize(source.size());
  pass.missed.resize(source.size(), 0);
  pass.missed_at.resize(source.size());
  pass.missed_reach.resize(source.size(), 0.0);
  pass.has_match.resize(source.size(), 0);
  // Reuse keeps the last residual signs: a point without a match stays without one.
  std::vector<double> last = std::move(pass.residuals);
  pass.residuals.assign(source.size(), -1.0);
  // A pass that searches few points or none (reuse) takes well under a millisecond: alone it
  // beats paying a fork-join, which on a busy machine can wait out another job's time slice.
  [[maybe_unused]] const std::size_t searched =
      search == Search::Reuse ? 0 : source.size() / static_cast<std::size_t>(stride);
#pragma omp parallel for schedule(dynamic, 4) if (searched >= kParallelSearches)
  for (long b = 0; b < static_cast<long>(blocks); ++b) {
    LinearSystem& system = partial[static_cast<std::size_t>(b)];
    const std::size_t begin = static_cast<std::size_t>(b) * kBlockSize;
    const std::size_t end = std::min(source.size(), begin + kBlockSize);
    const std::size_t stride_size = static_cast<std::size_t>(stride);
    const Point* found_before = nullptr;  // the map point this block's last search found
    for (std::size_t i = (begin + stride_size - 1) / stride_size * stride_size; i < end; i += stride_size) {
      if (search == Search::Reuse && !(i < last.size() && last[i] >= 0.0)) continue;
      if (search == Search::SkipMisses && pass.missed[i] != 0) continue;
      const Point moved = pose * source[i];
      if (search != Search::Reuse) {
        // A point that found nothing within a reach has nothing within that reach less how far
        // it moved since: where that still covers the gate, a search would find nothing again
        // (parts of the scan the map never saw: a third of a pass from a far start, whose
        // searches visit the whole gate).
        if (pass.missed[i] != 0 && pass.missed_reach[i] - (moved - pass.missed_at[i]).norm() > gate * (1.0 + 1e-9))
          continue;
        // Any map point bounds the distance to the nearest: a search of that radius (most
        // often within a voxel, where the gate spans blocks) finds the same point as one of
        // the gate. The point's own last match lies where it lay; a point without one (the
        // fine stage's first pass after the coarse stage's sample) takes the one its
        // predecessor in the block just found, centimetres off along the scan line.
        double reach = gate;
        if (pass.has_match[i] != 0) reach = std::min(gate, (moved - pass.matches[i].point).norm() * (1.0 + 1e-9));
        if (found_before != nullptr) reach = std::min(reach, (moved - *found_before).norm() * (1.0 + 1e-9));
        std::optional<Neighbour> neighbour = target.nearest(moved, reach);
        if (!neighbour && reach < gate) neighbour = target.nearest(moved, gate);
        pass.missed[i] = neighbour ? 0 : 1;
        if (!neighbour) {
          pass.missed_at[i] = moved;
          pass.missed_reach[i] = gate;
        }
        if (!neighbour || (metric == IcpMetric::PointToPlane && neighbour->normal.isZero())) continue;
        pass.matches[i] = *neighbour;
        pass.has_match[i] = 1;
        found_before = &pass.matches[i].point;
      }
      pass.residuals[i] = addTerm(moved, pass.matches[i], metric, scale_sq, pivot, system);
    }
  }
  pass.system = LinearSystem{};
  for (const LinearSystem& system : partial) pass.system += system;
}

// The robust spread of the residuals (their median absolute value as a sigma), with the
// number of correspondences and their RMS residual.
double residualSpread(const std::vector<double>& residuals, std::size_t& inliers, double& rms) {
  std::vector<double> magnitudes;
  magnitudes.reserve(residuals.size());
  double sum_sq = 0.0;
  for (const double residual : residuals) {
    if (residual < 0.0) continue;
    magnitudes.push_back(residual);
    sum_sq += residual * residual;
  }
  inliers = magnitudes.size();
  rms = inliers > 0 ? std::sqrt(sum_sq / static_cast<double>(inliers)) : 0.0;
  if (magnitudes.empty()) return 0.0;
  auto middle = magnitudes.begin() + static_cast<long>(magnitudes.size() / 2);
  std::nth_element(magnitudes.begin(), middle, magnitudes.end());
  return kMadToSigma * *middle;
}

// Solves H·δ = −g in the eigenbasis of H with rotations scaled to metres at `radius`;
// directions whose eigenvalue is below min_ratio·λ_max are left unchanged (solution
// remapping), so a corridor keeps its initial guess along its axis.
Vector6d solve(const LinearSystem& system, double radius, double min_ratio, double& ratio) {
  Vector6d scaling;
  scaling << Eigen::Vector3d::Constant(1.0 / radius), Eigen::Vector3d::Ones();
  const Matrix6d hessian = scaling.asDiagonal() * system.hessian * scaling.asDiagonal();
  const Vector6d gradient = scaling.asDiagonal() * system.gradient;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(hessian);
  const Vector6d eigenvalues = solver.eigenvalues();  // ascending
  const double largest = eigenvalues[5];
  ratio = largest > 0.0 ? std::max(0.0, eigenvalues[0]) / largest : 0.0;
  Vector6d step = Vector6d::Zero();
  for (int k = 0; k < 6; ++k) {
    if (!(eigenvalues[k] > min_ratio * largest)) continue;
    const Vector6d direction = solver.eigenvectors().col(k);
    step -= direction * (direction.dot(gradient) / eigenvalues[k]);
  }
  return scaling.asDiagonal() * step;
}

// The coarse stage's extrapolation (see kExtrapolateCosine): after `step` (already applied to
// result.pose), when it continues `previous` (scaled: rotations in metres at `radius`) and is
// shorter, moves the pose on by the series' remainder; returns how far that moved points (m).
// A jump starts the series anew: the next two steps decide the next one.
double extrapolate(const Vector6d& step, double radius, double gate, Vector6d& previous, IcpResult& result) {
  Vector6d scaled;
  scaled << step.head<3>() * radius, step.tail<3>();
  const double length = scaled.norm();
  const double previous_length = previous.norm();
  const double cosine_scaled = scaled.dot(previous);  // cos · |step| · |previous|
  previous = scaled;
  if (!(length > 0.0) || !(previous_length > length)) return 0.0;
  if (cosine_scaled < kExtrapolateCosine * length * previous_length) return 0.0;
  const double ratio = length / previous_length;
  const double motion = step.tail<3>().norm() + step.head<3>().norm() * radius;
  const double factor = std::min(ratio / (1.0 - ratio), kExtrapolateGateShare * gate / motion);
  result.pose = applyIncrement(factor * step, result.pivot, result.pose);
  previous.setZero();
  return factor * motion;
}

}  // namespace

Pose applyIncrement(const Vector6d& increment, const Eigen::Vector3d& pivot, const Pose& pose) {
  const Eigen::Vector3d omega = increment.head<3>();
  const double angle = omega.norm();
  const Eigen::Matrix3d rotation =
      angle > 0.0 ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
  Pose delta = Pose::Identity();
  delta.linear() = rotation;
  delta.translation() = pivot + increment.tail<3>() - rotation * pivot;
  return delta * pose;
}

Vector6d incrementOf(const Pose& delta, const Eigen::Vector3d& pivot) {
  const Eigen::AngleAxisd angle_axis(delta.linear());
  Vector6d increment;
  increment << angle_axis.angle() * angle_axis.axis(),
      delta.translation() - pivot + delta.linear() * pivot;
  return increment;
}

IcpResult alignPoints(const std::vector<Point>& source, const VoxelHashMap& target,
                      const Pose& initial_guess, const IcpConfig& config) {
  IcpResult result;
  result.pose = initial_guess;
  result.pivot = initial_guess.translation();
  result.source_points = source.size();
  if (source.empty() || target.empty()) return result;

  // The cloud's radius around the sensor turns rotations into metres (point motion,
  // eigenvalue scaling).
  double radius_sq = 0.0;
  for (const Point& point : source) radius_sq += point.squaredNorm();
  const double radius = std::max(1.0, std::sqrt(radius_sq / static_cast<double>(source.size())));
  result.radius = radius;

  Pass pass;
  double gate = config.initial_max_distance;
  // Coarse stage: while the pose may still be far off, every search reaches far (a wide
  // gate visits hundreds of voxels), so a sparse, evenly spread subset of the source steers
  // with the gate held wide until the pose stops moving. The fine stage then refines with
  // every point and the adaptive gate, where a search visits a handful of voxels.
  bool coarse = true;
  bool dense = false;  // the fine stage searches every point (after the middle stage)
  const double dense_gate = kDenseGateFactor * config.min_max_distance;
  int coarse_iterations = 0;
  int middle_iterations = 0;
  bool reuse = false;
  double moved_since_search = std::numeric_limits<double>::infinity();  // m, since the last Search::All
  LinearSystem system;
  Vector6d previous_step = Vector6d::Zero();  // the coarse stage's last step, rotations in metres
  for (int iteration = 0; iteration < config.max_iterations; ++iteration) {
    const long stride = coarse ? sampleStride(source.size(), kCoarsePoints)
                        : dense ? 1
                                : sampleStride(source.size(), kMiddlePoints);
    // The kernel scale is a third of the gate: while the pose is still uncertain every
    // correspondence in the gate pulls, even when most residuals are already small. In the
    // coarse stage the gate is wide to reach far partners, and a tighter kernel keeps the
    // mismatches it admits from steering.
    result.kernel_scale = std::max(config.min_kernel_scale, gate / (coarse ? kCoarseKernelDivisor : 3.0));
    Search search = Search::All;
    if (reuse) {
      search = Search::Reuse;
    } else if (moved_since_search < kMissMotion * gate) {
      search = Search::SkipMisses;
    } else {
      moved_since_search = 0.0;
    }
    associateAndBuild(source, target, result.pose, gate, config.metric, stride, search, result.kernel_scale,
                      result.pivot, pass);
    const double spread = residualSpread(pass.residuals, result.inliers, result.rms_residual);
    result.iterations = iteration + 1;
    if (result.inliers < 6) {
      if (coarse || !dense) {  // too few sampled points matched: let every point try
        coarse = false;
        dense = true;
        moved_since_search = std::numeric_limits<double>::infinity();
        continue;
      }
      break;
    }
    system = pass.system;
    // Directions the coarse stage constrains only weakly (along a corridor) are left to the
    // fine stage, whose correspondences are right: wide-gate mismatches would push them.
    const double min_ratio = (coarse ? kCoarseEigenvalueFactor : 1.0) * config.min_eigenvalue_ratio;
    const Vector6d step = solve(system, radius, min_ratio, result.eigenvalue_ratio);
    result.pose = applyIncrement(step, result.pivot, result.pose);

    const double step_translation = step.tail<3>().norm();
    const double step_rotation = step.head<3>().norm();
    double motion = step_translation + step_rotation * radius;
    // A step that settles the coarse stage ends it as it is.
    if (coarse && motion >= kCoarseSettledMotion * config.min_max_distance) {
      motion += extrapolate(step, radius, gate, previous_step, result);
    }
    moved_since_search += motion;
    // The adaptive threshold: the gate follows the residual spread plus how far points
    // just moved, so it stays wide while the pose still travels and closes in once it
    // settles (never below min_max_distance).
    const double next_gate =
        std::max(config.min_max_distance, std::min(gate, 3.0 * spread + 2.0 * motion));
    if (coarse) {
      ++coarse_iterations;
      if (motion < kCoarseSettledMotion * config.min_max_distance || coarse_iterations >= kMaxCoarseIterations) {
        coarse = false;
        gate = std::max(config.min_max_distance, std::min(next_gate, config.max_fine_distance));
        dense = gate <= dense_gate;
      }
      continue;
    }
    if (!dense) {
      ++middle_iterations;
      dense = next_gate <= dense_gate || motion < kCoarseSettledMotion * config.min_max_distance ||
              middle_iterations >= kMaxCoarseIterations;
      gate = next_gate;
      continue;
    }
    const bool settled = gate - next_gate < 0.01 * gate;
    reuse = gate == next_gate && motion < kReuseMotion * config.min_kernel_scale;
    gate = next_gate;
    if (settled && step_translation < config.convergence_translation &&
        step_rotation < config.convergence_rotation) {
      result.converged = true;
      break;
    }
  }
  result.hessian = system.hessian;
  result.degenerate = result.eigenvalue_ratio < config.min_eigenvalue_ratio;
  result.unreliable = result.inliers < config.min_inliers || result.degenerate || !result.converged;
  return result;
}

}  // namespace mlmap::registration
