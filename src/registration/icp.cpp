// The ICP loop as a few named steps (transform + associate, adapt the kernel, build the
// normal equations, solve, update, converged?), like KISS-ICP's Registration.cpp.
#include "mlmap/registration/icp.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace mlmap::registration {
namespace {

constexpr double kMadToSigma = 1.4826;  // MAD -> standard deviation of a Gaussian
constexpr std::size_t kBlockSize = 512; // points per partial sum of the reduction

struct Correspondence {
  Point source;  // transformed into the target frame
  Point target;
  Normal normal;
  bool valid = false;
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

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// Every `stride`-th source point gets a correspondence; the others are marked invalid.
void associate(const std::vector<Point>& source, const VoxelHashMap& target, const Pose& pose,
               double gate, IcpMetric metric, long stride, std::vector<Correspondence>& correspondences) {
  const long count = static_cast<long>(source.size());
#pragma omp parallel for schedule(dynamic, 1024)
  for (long i = 0; i < count; ++i) {
    Correspondence& c = correspondences[static_cast<std::size_t>(i)];
    c.valid = false;
    if (i % stride != 0) continue;
    c.source = pose * source[static_cast<std::size_t>(i)];
    const auto neighbour = target.nearest(c.source, gate);
    c.valid = neighbour && (metric == IcpMetric::PointToPoint || !neighbour->normal.isZero());
    if (!c.valid) continue;
    c.target = neighbour->point;
    c.normal = neighbour->normal;
  }
}

double residualNorm(const Correspondence& c, IcpMetric metric) {
  return metric == IcpMetric::PointToPlane ? std::abs(c.normal.dot(c.source - c.target))
                                           : (c.source - c.target).norm();
}

// The robust spread of the residuals (their median absolute value as a sigma), with the
// number of correspondences and their RMS residual.
double residualSpread(const std::vector<Correspondence>& correspondences, IcpMetric metric,
                      std::size_t& inliers, double& rms) {
  std::vector<double> magnitudes;
  magnitudes.reserve(correspondences.size());
  double sum_sq = 0.0;
  for (const Correspondence& c : correspondences) {
    if (!c.valid) continue;
    magnitudes.push_back(residualNorm(c, metric));
    sum_sq += magnitudes.back() * magnitudes.back();
  }
  inliers = magnitudes.size();
  rms = inliers > 0 ? std::sqrt(sum_sq / static_cast<double>(inliers)) : 0.0;
  if (magnitudes.empty()) return 0.0;
  auto middle = magnitudes.begin() + static_cast<long>(magnitudes.size() / 2);
  std::nth_element(magnitudes.begin(), middle, magnitudes.end());
  return kMadToSigma * *middle;
}

// Σ w·JᵀJ and Σ w·Jᵀr for the increment (ω about `pivot`, v), Geman–McClure weights.
// Partial sums over fixed blocks, added in block order: the same result at any thread count.
LinearSystem buildSystem(const std::vector<Correspondence>& correspondences, IcpMetric metric,
                         double scale, const Eigen::Vector3d& pivot) {
  const double scale_sq = scale * scale;
  const std::size_t blocks = (correspondences.size() + kBlockSize - 1) / kBlockSize;
  std::vector<LinearSystem> partial(blocks);
#pragma omp parallel for schedule(static)
  for (long b = 0; b < static_cast<long>(blocks); ++b) {
    LinearSystem& system = partial[static_cast<std::size_t>(b)];
    const std::size_t end = std::min(correspondences.size(), (static_cast<std::size_t>(b) + 1) * kBlockSize);
    for (std::size_t i = static_cast<std::size_t>(b) * kBlockSize; i < end; ++i) {
      const Correspondence& c = correspondences[i];
      if (!c.valid) continue;
      const Eigen::Vector3d arm = c.source - pivot;
      if (metric == IcpMetric::PointToPlane) {
        const double residual = c.normal.dot(c.source - c.target);
        Vector6d jacobian;
        jacobian << arm.cross(c.normal), c.normal;
        const double weight = std::pow(scale_sq / (scale_sq + residual * residual), 2);
        system.hessian.noalias() += weight * jacobian * jacobian.transpose();
        system.gradient.noalias() += weight * residual * jacobian;
      } else {
        const Eigen::Vector3d residual = c.source - c.target;
        Eigen::Matrix<double, 3, 6> jacobian;
        jacobian << -skew(arm), Eigen::Matrix3d::Identity();
        const double weight = std::pow(scale_sq / (scale_sq + residual.squaredNorm()), 2);
        system.hessian.noalias() += weight * jacobian.transpose() * jacobian;
        system.gradient.noalias() += weight * jacobian.transpose() * residual;
      }
    }
  }
  LinearSystem total;
  for (const LinearSystem& system : partial) total += system;
  return total;
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

  std::vector<Correspondence> correspondences(source.size());
  double gate = config.initial_max_distance;
  LinearSystem system;
  for (int iteration = 0; iteration < config.max_iterations; ++iteration) {
    // In the first iterations, while the gate is wide (the pose still far off, every
    // search expensive), a quarter of the source points steers; all of them refine.
    const long stride = iteration < 5 && gate > 2.0 * config.min_max_distance ? 4 : 1;
    associate(source, target, result.pose, gate, config.metric, stride, correspondences);
    const double spread = residualSpread(correspondences, config.metric, result.inliers, result.rms_residual);
    // The kernel scale is a third of the gate: while the pose is still uncertain every
    // correspondence in the gate pulls, even when most residuals are already small.
    result.kernel_scale = std::max(config.min_kernel_scale, gate / 3.0);
    result.iterations = iteration + 1;
    if (result.inliers < 6) break;
    system = buildSystem(correspondences, config.metric, result.kernel_scale, result.pivot);
    const Vector6d step = solve(system, radius, config.min_eigenvalue_ratio, result.eigenvalue_ratio);
    result.pose = applyIncrement(step, result.pivot, result.pose);

    // The adaptive threshold: the gate follows the residual spread plus how far points
    // just moved, so it stays wide while the pose still travels and closes in once it
    // settles (never below min_max_distance).
    const double step_translation = step.tail<3>().norm();
    const double step_rotation = step.head<3>().norm();
    const double motion = step_translation + step_rotation * radius;
    const double next_gate =
        std::max(config.min_max_distance, std::min(gate, 3.0 * spread + 2.0 * motion));
    const bool settled = gate - next_gate < 0.01 * gate && stride == 1;
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
