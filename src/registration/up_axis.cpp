#include "mlmap/registration/up_axis.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>
#include <unordered_map>

namespace mlmap::registration {
namespace {

// A cell's points: their moments, and per axis how many lie below their sensor.
struct CellSums {
  std::size_t count = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  std::array<std::size_t, 3> below{};
};

// Fewer points do not fix a plane against the noise; a cell of 0.2 m holds hundreds
// on a surface a few metres off.
constexpr std::size_t kMinCellPoints = 8;
// Flat: the smallest spread under a fifth of the middle one (σ_min/σ_mid < 0.22): a
// plane with a few cm of noise in a 0.2 m cell, not a corner or a chair leg.
constexpr double kFlatness = 0.05;
// A cell faces an axis within 15 deg; a turn counts from 10 deg (under it, the axis of
// a turn is the noise of the poses).
const double kFacingCos = std::cos(15.0 * std::numbers::pi / 180.0);
constexpr double kMinTurnRad = 10.0 * std::numbers::pi / 180.0;
const double kSnapCos = std::cos(10.0 * std::numbers::pi / 180.0);
constexpr std::size_t kMinPlanarCells = 20;

std::uint64_t cellKey(const Eigen::Vector3d& point, double cell_size) {
  const auto part = [&](double value) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(value / cell_size)) + (1 << 20)) & 0x1FFFFF;
  };
  return part(point.x()) | part(point.y()) << 21 | part(point.z()) << 42;
}

// The coordinate axis (0, 1, 2) within kSnapCos of `direction`, or -1.
int snappedAxis(const Eigen::Vector3d& direction) {
  Eigen::Index axis = 0;
  const double largest = direction.cwiseAbs().maxCoeff(&axis);
  return largest >= kSnapCos * direction.norm() ? static_cast<int>(axis) : -1;
}

// The axis the poses turn about, when they turn: their rotations relative to the first.
int turnAxis(const std::vector<Pose>& poses) {
  Eigen::Vector3d summed = Eigen::Vector3d::Zero();
  for (std::size_t k = 1; k < poses.size(); ++k) {
    const Eigen::AngleAxisd turn(poses[k].linear() * poses.front().linear().transpose());
    if (turn.angle() < kMinTurnRad) continue;
    const Eigen::Vector3d axis = turn.axis().dot(summed) < 0.0 ? Eigen::Vector3d(-turn.axis()) : turn.axis();
    summed += turn.angle() * axis;
  }
  return summed.norm() > 0.0 ? snappedAxis(summed) : -1;
}

// The sensors moved in a plane when their positions spread across it by at least this
// (standard deviation, m: a corridor's zig-zag of a few decimetres) and out of it by at most
// this share of that (a robot's scanner height holds to a centimetre over metres; a hand-held
// sensor's bobs by a tenth of its spread or more, and tells nothing).
constexpr double kMinPlaneSpread = 0.1;
constexpr double kMaxOutOfPlane = 0.1;

// The coordinate axis normal to the plane the poses' positions lie in, or -1.
int movedPlaneAxis(const std::vector<Pose>& poses) {
  if (poses.size() < 3) return -1;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Pose& pose : poses) mean += pose.translation();
  mean /= static_cast<double>(poses.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Pose& pose : poses) {
    const Eigen::Vector3d d = pose.translation() - mean;
    covariance += d * d.transpose();
  }
  covariance /= static_cast<double>(poses.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Eigen::Vector3d values = solver.eigenvalues().cwiseMax(0.0);  // ascending
  if (!(std::sqrt(values(1)) >= kMinPlaneSpread)) return -1;
  if (!(std::sqrt(values(0)) <= kMaxOutOfPlane * std::sqrt(values(1)))) return -1;
  return snappedAxis(solver.eigenvectors().col(0));
}

// A depth image is a camera's view when this share of its points lies in front of it (its
// optical frame's +z); a spinning lidar's organized scan (rows of rings) lies all round.
constexpr double kMinInFront = 0.95;

// The signed coordinate axis the image's down (the optical frame's +y, turned by each pose)
// lies along, summed over the scans read from depth images that are camera views; zero
// where there are none or the sum is more than kSnapCos off every axis (a camera looking
// down at a table).
Eigen::Vector3d imageDown(const std::vector<Scan>& scans) {
  Eigen::Vector3d summed = Eigen::Vector3d::Zero();
  for (const Scan& scan : scans) {
    if (!scan.from_image || scan.points.empty()) continue;
    const auto in_front = std::count_if(scan.points.begin(), scan.points.end(),
                                        [](const Point& point) { return point.z() > 0.0; });
    if (static_cast<double>(in_front) < kMinInFront * static_cast<double>(scan.points.size())) continue;
    summed += scan.pose.linear() * Eigen::Vector3d::UnitY();
  }
  const int axis = summed.norm() > 0.0 ? snappedAxis(summed) : -1;
  Eigen::Vector3d down = Eigen::Vector3d::Zero();
  if (axis >= 0) down[axis] = summed[axis] > 0.0 ? 1.0 : -1.0;
  return down;
}

// A level cell's normal lies this far from the level surfaces' at most: more is a ramp, a
// chair's tilted seat or a cell holding a step's edge. The simulated lab pitched 3 deg and
// rolled 1 deg (3.16 deg) measures 3.15 deg with it.
constexpr double kLevelSpreadDeg = 3.0;

// The mean of the facing cells' normals weighted by their points, twice again without
// those more than kLevelSpreadDeg from it; none where fewer than kMinPlanarCells remain.
std::optional<Eigen::Vector3d> meanDirection(const std::vector<std::pair<Eigen::Vector3d, double>>& normals) {
  if (normals.size() < kMinPlanarCells) return std::nullopt;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& [normal, weight] : normals) mean += weight * normal;
  const double keep = std::cos(kLevelSpreadDeg * std::numbers::pi / 180.0);
  for (int round = 0; round < 2; ++round) {
    const Eigen::Vector3d centre = mean.normalized();
    Eigen::Vector3d next = Eigen::Vector3d::Zero();
    std::size_t kept = 0;
    for (const auto& [normal, weight] : normals) {
      if (normal.dot(centre) < keep) continue;
      next += weight * normal;
      ++kept;
    }
    if (kept < kMinPlanarCells) return std::nullopt;
    mean = next;
  }
  return mean.normalized();
}

// Each planar cell of the scans' points (thinned evenly to config.max_points) with its
// normal: cells of config.cell_size holding kMinCellPoints or more whose smallest spread is
// under kFlatness of the middle one.
template <typename Visit>
void forEachPlanarCell(const std::vector<Scan>& scans, const UpAxisConfig& config, Visit&& visit) {
  std::size_t total = 0;
  for (const Scan& scan : scans) total += scan.size();
  const std::size_t stride = config.max_points == 0 ? 1 : std::max<std::size_t>(1, total / config.max_points + 1);
  std::unordered_map<std::uint64_t, CellSums> cells;
  std::size_t running = 0;
  for (const Scan& scan : scans) {
    const Eigen::Vector3d origin = scan.pose.translation();
    for (const Point& sensor_point : scan.points) {
      if (running++ % stride != 0) continue;
      const Eigen::Vector3d point = scan.pose * sensor_point;
      CellSums& cell = cells[cellKey(point, config.cell_size)];
      ++cell.count;
      cell.sum += point;
      cell.outer += point * point.transpose();
      for (int axis = 0; axis < 3; ++axis) cell.below[axis] += point[axis] < origin[axis] ? 1 : 0;
    }
  }
  for (const auto& [key, cell] : cells) {
    if (cell.count < kMinCellPoints) continue;
    const double n = static_cast<double>(cell.count);
    const Eigen::Vector3d mean = cell.sum / n;
    const Eigen::Matrix3d covariance = cell.outer / n - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
    const Eigen::Vector3d values = solver.eigenvalues();  // ascending
    if (!(values(0) < kFlatness * values(1))) continue;
    visit(Eigen::Vector3d(solver.eigenvectors().col(0)), cell);
  }
}

}  // namespace

UpAxisEstimate estimateUpAxis(const std::vector<Scan>& scans, const UpAxisConfig& config,
                              const std::vector<Pose>& sequence_poses) {
  // Planar cells by the axis they face (-1: none), with their points.
  std::array<std::size_t, 3> facing{}, below{}, on_family{};
  UpAxisEstimate estimate;
  forEachPlanarCell(scans, config, [&](const Eigen::Vector3d& normal, const CellSums& cell) {
    ++estimate.planar_cells;
    Eigen::Index axis = 0;
    if (normal.cwiseAbs().maxCoeff(&axis) < kFacingCos) return;
    const auto a = static_cast<std::size_t>(axis);
    ++facing[a];
    on_family[a] += cell.count;
    below[a] += cell.below[a];
  });

  std::vector<Pose> poses = sequence_poses;
  if (poses.empty()) {
    for (const Scan& scan : scans) poses.push_back(scan.pose);
  }
  int line = turnAxis(poses);
  const Eigen::Vector3d down = imageDown(scans);
  if (line >= 0) {
    estimate.line_from = UpCue::Poses;
  } else if ((line = movedPlaneAxis(poses)) >= 0) {
    estimate.line_from = UpCue::Positions;
  } else if (!down.isZero()) {
    Eigen::Index axis = 0;
    down.cwiseAbs().maxCoeff(&axis);
    line = static_cast<int>(axis);
    estimate.line_from = UpCue::Image;
    // A camera looking down at a table: its image's down is the nearest axis to up, but
    // the surfaces say the view is tilted.
    estimate.faces_no_axis = estimate.planar_cells >= kMinPlanarCells &&
                             *std::max_element(facing.begin(), facing.end()) < kMinPlanarCells;
  } else if (const auto most = std::max_element(facing.begin(), facing.end()); *most >= kMinPlanarCells) {
    // A family of its own: where the planar cells face no coordinate axis (a camera looking
    // down at a table, its plane 32 deg from every axis), no axis is the line.
    line = static_cast<int>(most - facing.begin());
    estimate.line_from = UpCue::Planes;
  } else {
    estimate.faces_no_axis = estimate.planar_cells >= kMinPlanarCells;
    return estimate;  // no evidence: +z
  }
  const auto axis = static_cast<std::size_t>(line);
  estimate.planar_share = estimate.planar_cells == 0
                              ? 0.0
                              : static_cast<double>(facing[axis]) / static_cast<double>(estimate.planar_cells);
  estimate.below_share =
      on_family[axis] == 0 ? 0.5 : static_cast<double>(below[axis]) / static_cast<double>(on_family[axis]);
  estimate.up = Eigen::Vector3d::Zero();
  // A tie keeps the positive axis: no evidence against the data's own convention. The
  // image's down gives its own sign: a view of a wall puts it all on one side of the camera.
  if (estimate.line_from == UpCue::Image) estimate.up = -down;
  else estimate.up[line] = estimate.below_share >= 0.5 ? 1.0 : -1.0;
  return estimate;
}

Eigen::Matrix3d rotationToLevel(const Eigen::Vector3d& normal) {
  return Eigen::Quaterniond::FromTwoVectors(normal.normalized(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

std::optional<Eigen::Vector3d> levelNormal(const std::vector<Scan>& scans, const Eigen::Vector3d& up,
                                           const UpAxisConfig& config) {
  const Eigen::Vector3d axis = up.normalized();
  std::vector<std::pair<Eigen::Vector3d, double>> normals;
  forEachPlanarCell(scans, config, [&](const Eigen::Vector3d& normal, const CellSums& cell) {
    const double along = normal.dot(axis);
    if (std::abs(along) >= kFacingCos)
      normals.emplace_back(along < 0.0 ? Eigen::Vector3d(-normal) : normal, static_cast<double>(cell.count));
  });
  return meanDirection(normals);
}

Eigen::Matrix3d rotationToZUp(const Eigen::Vector3d& up) {
  const Eigen::Vector3d unit = up.normalized();
  if (unit.z() > 0.5) return Eigen::Matrix3d::Identity();
  if (unit.z() < -0.5) return Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return Eigen::Quaterniond::FromTwoVectors(unit, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

const char* axisName(const Eigen::Vector3d& up) {
  Eigen::Index axis = 0;
  up.cwiseAbs().maxCoeff(&axis);
  static constexpr std::array<const char*, 6> kNames{"+x", "+y", "+z", "-x", "-y", "-z"};
  return kNames[static_cast<std::size_t>(axis + (up[axis] < 0.0 ? 3 : 0))];
}

}  // namespace mlmap::registration
