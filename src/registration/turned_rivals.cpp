#include "turned_rivals.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace mlmap::registration {
namespace {

// The horizontal extent is taken between these quantiles of the points' x and y: a few
// readings through a doorway or a window would otherwise move the centre of a room.
constexpr double kExtentQuantile = 0.02;
// The screen of a turn looks at about this many of the source's points (the walls of them),
// and lets ICP run where at least kScreenShare as many lie near the target turned as at the
// result. Measured on the tuning split: furnished rooms 0.43-0.71 (at 0.5 a rival ran for most
// room pairs, 20-30 ms each), the symmetric room 0.59-1.24 (probably the scans' 90 deg blind
// sector: turned walls fall where the target saw nothing), the lab's and the corridors'
// quarter turns 0.04-0.31.
constexpr std::size_t kScreenPoints = 1000;
constexpr double kScreenShare = 0.6;
// rad: a quarter turn and 10 deg for the scatter of ICP's answers.
constexpr double kMaxStartTurn = 100.0 * std::numbers::pi / 180.0;
// A rival runs first on every kSampleStep-th source point, and on all of them only where that
// sample explains at least rival_share of what the result explains of it.
constexpr std::size_t kSampleStep = 8;
// ... and at most this many iterations: from a turn of a room about its centre a rival that
// fits converges in 5-8 (the tuning split's symmetric room), one that does not wanders on to
// the limit of 60 (its furnished rooms: 40-60 iterations, 30-55 ms on a 1,000-2,000 point sample).
constexpr int kSampleIterations = 12;
constexpr double kLevelNormal = 0.7071;  // as verifyAlignment's kinds of surface

double quantile(std::vector<double>& values, double q) {
  const auto at = values.begin() + static_cast<long>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

Eigen::Vector2d extentCentre(const std::vector<Point>& source, const Pose& pose) {
  std::vector<double> xs;
  std::vector<double> ys;
  xs.reserve(source.size());
  ys.reserve(source.size());
  for (const Point& point : source) {
    const Point moved = pose * point;
    xs.push_back(moved.x());
    ys.push_back(moved.y());
  }
  const double x = 0.5 * (quantile(xs, kExtentQuantile) + quantile(xs, 1.0 - kExtentQuantile));
  const double y = 0.5 * (quantile(ys, kExtentQuantile) + quantile(ys, 1.0 - kExtentQuantile));
  return {x, y};
}

// The source's wall points (normal within 45 deg of horizontal), every so many: a floor lies
// on the target's floor at any turn, so only walls tell a turn apart.
std::vector<Point> wallSample(const std::vector<Point>& source, const std::vector<Eigen::Vector3d>& normals) {
  std::vector<Point> walls;
  const std::size_t step = std::max<std::size_t>(1, source.size() / kScreenPoints);
  for (std::size_t k = 0; k < source.size() && k < normals.size(); k += step) {
    if (!normals[k].isZero() && std::abs(normals[k].z()) < kLevelNormal) walls.push_back(source[k]);
  }
  return walls;
}

std::size_t nearCount(const std::vector<Point>& points, const VoxelHashMap& target, const Pose& pose, double reach) {
  std::size_t near = 0;
  for (const Point& point : points) near += target.nearest(pose * point, reach).has_value() ? 1 : 0;
  return near;
}

}  // namespace

std::vector<TurnedRival> turnedRivals(const std::vector<Point>& source, const std::vector<Eigen::Vector3d>& normals,
                                      const VoxelHashMap& target, const Pose& pose, const Pose& start,
                                      const IcpConfig& icp, double sigma, double gate, const BasinConfig& config) {
  std::vector<TurnedRival> rivals;
  if (source.empty()) return rivals;
  const Eigen::Vector2d centre2 = extentCentre(source, pose);
  const Eigen::Vector3d centre(centre2.x(), centre2.y(), 0.0);
  const std::vector<Point> walls = wallSample(source, normals);
  const double reach = icp.initial_max_distance;
  const double kept_near = static_cast<double>(nearCount(walls, target, pose, reach));
  std::vector<Point> sample;
  for (std::size_t k = 0; k < source.size(); k += kSampleStep) sample.push_back(source[k]);
  const double kept_sample_share = verifyAlignment(sample, target, pose, sigma, gate, config).explained_share;
  IcpConfig sample_icp = icp;
  sample_icp.max_iterations = std::min(icp.max_iterations, kSampleIterations);
  for (const double turn_deg : {90.0, 180.0, 270.0}) {
    // About the target's vertical: the floor stays level, only the heading and the place change.
    Pose turn = Pose::Identity();
    turn.linear() = Eigen::AngleAxisd(turn_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    turn.translation() = centre - turn.linear() * centre;
    TurnedRival rival;
    rival.turn_deg = turn_deg;
    rival.icp.pose = turn * pose;
    // A start is taken to be within a quarter turn of the truth (the far starts measured:
    // up to 90 deg); a rival further from it is none it could have meant. This leaves out the
    // half turn, which maps every rectangular room onto itself, unless the result itself is
    // more than a quarter turn from the start.
    const double from_start = Eigen::AngleAxisd(start.linear().transpose() * rival.icp.pose.linear()).angle();
    if (from_start > kMaxStartTurn) {
      rivals.push_back(std::move(rival));
      continue;
    }
    // ICP only where the turned walls lie within its first gate of the target about as often
    // as the result's: an open scene or a room of unequal sides leaves most of them beyond
    // (a few hundred lookups against a run of 10-40 ms).
    if (static_cast<double>(nearCount(walls, target, rival.icp.pose, reach)) < kScreenShare * kept_near) {
      rivals.push_back(std::move(rival));
      continue;
    }
    // First on a sample; on every point only where the sample makes it a rival.
    rival.icp = alignPoints(sample, target, rival.icp.pose, sample_icp);
    const Verification rough = verifyAlignment(sample, target, rival.icp.pose, sigma, gate, config);
    rival.ran = true;
    if (rough.good && rough.explained_share >= config.rival_share * kept_sample_share) {
      rival.icp = alignPoints(source, target, rival.icp.pose, icp);
      rival.check = verifyAlignment(source, target, rival.icp.pose, sigma, gate, config);
    }
    rivals.push_back(std::move(rival));
  }
  return rivals;
}

RivalVerdict judgeRivals(const std::vector<TurnedRival>& rivals, const Verification& kept, const BasinConfig& config) {
  RivalVerdict verdict;
  for (const TurnedRival& rival : rivals) {
    if (!rival.check.good) continue;
    if (verdict.best == nullptr || rival.check.explained_share > verdict.best->check.explained_share) {
      verdict.best = &rival;
    }
  }
  if (verdict.best == nullptr) return verdict;
  const double best_share = verdict.best->check.explained_share;
  if (best_share < config.rival_share * kept.explained_share) return verdict;
  if (best_share < config.rival_replace * kept.explained_share) {
    verdict.ambiguous = true;  // too close to tell
    return verdict;
  }
  // The kept result was itself the turned one: the rival is the better-explained answer, if
  // no third comes close to it.
  verdict.replaces = true;
  verdict.ambiguous = std::any_of(rivals.begin(), rivals.end(), [&](const TurnedRival& rival) {
    return &rival != verdict.best && rival.check.good && rival.check.explained_share >= config.rival_share * best_share;
  });
  return verdict;
}

}  // namespace mlmap::registration
