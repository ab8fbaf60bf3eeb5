#include "mlmap/registration/voxel_hash_map.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "mlmap/error.hpp"

namespace mlmap::registration {
namespace {

constexpr long kKeyCentre = 32768;  // octomap's tree_max_val at depth 16
constexpr long kKeyMax = 65535;

// Running sums of a neighbourhood for its PCA.
struct Moments {
  std::size_t count = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();  // Σ (p − reference)(p − reference)ᵀ
  Point reference = Point::Zero();                  // subtracted first, for precision far from 0
  void add(const Point& point) {
    const Eigen::Vector3d d = point - reference;
    ++count;
    sum += d;
    outer.noalias() += d * d.transpose();
  }
};

// The PCA normal of a neighbourhood, or zero when it is not planar.
Normal planeNormal(const Moments& moments, const NormalConfig& config) {
  if (moments.count < config.min_neighbours) return Normal::Zero();
  const double n = static_cast<double>(moments.count);
  const Eigen::Vector3d mean = moments.sum / n;
  const Eigen::Matrix3d covariance = moments.outer - n * mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Eigen::Vector3d eigenvalues = solver.eigenvalues();  // ascending
  const double total = eigenvalues.sum();
  // Planar: thin across (low curvature) and spread in two directions (not a line or a
  // strip of one scan line, whose normal can turn about the line).
  if (total > 0.0 && eigenvalues[0] / total <= config.max_curvature && eigenvalues[1] > 0.05 * eigenvalues[2]) {
    return solver.eigenvectors().col(0).normalized();
  }
  return Normal::Zero();
}

}  // namespace

VoxelHashMap::VoxelHashMap(double voxel_size, std::size_t max_points_per_voxel)
    : key_grid_(voxel_size > 0.0 ? voxel_size : 1.0), max_points_per_voxel_(max_points_per_voxel) {
  if (!(voxel_size > 0.0)) throw Error("voxel hash map: voxel size must be positive");
  if (max_points_per_voxel == 0) throw Error("voxel hash map: max points per voxel must be positive");
}

void VoxelHashMap::addPoints(const std::vector<Point>& points) {
  for (const Point& point : points) {
    octomap::OcTreeKey key;
    if (!key_grid_.coordToKeyChecked(point.x(), point.y(), point.z(), key)) continue;
    Voxel& voxel = voxels_[key];
    if (voxel.points.size() >= max_points_per_voxel_) continue;
    voxel.points.push_back(point);
    voxel.dirty = true;
    ++size_;
  }
}

// Calls visit(voxel) for each stored voxel within `radius` of `query` (its box, not its
// points), in shells of growing Chebyshev distance around the query's voxel, and stops
// once a shell lies beyond the radius. `visit` returns the radius to go on with, so a
// nearest-neighbour search shrinks it to the best distance found so far.
template <typename Visit>
void VoxelHashMap::visitVoxels(const Point& query, double radius, Visit&& visit) const {
  const double factor = 1.0 / key_grid_.getResolution();  // as OcTree's resolution_factor
  const double resolution = key_grid_.getResolution();
  long own[3], low[3], high[3];
  for (int axis = 0; axis < 3; ++axis) {
    const double c = query[axis];
    own[axis] = static_cast<long>(std::floor(c * factor)) + kKeyCentre;
    low[axis] = std::max(0L, static_cast<long>(std::floor((c - radius) * factor)) + kKeyCentre);
    high[axis] = std::min(kKeyMax, static_cast<long>(std::floor((c + radius) * factor)) + kKeyCentre);
    if (low[axis] > high[axis]) return;
  }
  const auto visitKey = [&](long x, long y, long z) {
    if (x < low[0] || x > high[0] || y < low[1] || y > high[1] || z < low[2] || z > high[2]) return;
    const long key[3] = {x, y, z};
    double box_distance_sq = 0.0;  // from the query to the voxel's box
    for (int axis = 0; axis < 3; ++axis) {
      const double lo = static_cast<double>(key[axis] - kKeyCentre) * resolution;
      const double gap = std::max({0.0, lo - query[axis], query[axis] - (lo + resolution)});
      box_distance_sq += gap * gap;
    }
    if (box_distance_sq > radius * radius) return;
    const auto found = voxels_.find(octomap::OcTreeKey(static_cast<octomap::key_type>(x),
                                                       static_cast<octomap::key_type>(y),
                                                       static_cast<octomap::key_type>(z)));
    if (found != voxels_.end()) radius = visit(found->second);
  };
  long max_shell = 0;
  for (int axis = 0; axis < 3; ++axis) {
    max_shell = std::max({max_shell, std::abs(own[axis] - low[axis]), std::abs(high[axis] - own[axis])});
  }
  for (long k = 0; k <= max_shell; ++k) {
    // Every voxel of shell k is at least (k − 1) voxels away from the query.
    if (static_cast<double>(k - 1) * resolution > radius) break;
    for (long dx = -k; dx <= k; ++dx) {
      for (long dy = -k; dy <= k; ++dy) {
        const bool on_face = std::abs(dx) == k || std::abs(dy) == k;
        for (long dz = -k; dz <= k; dz += (on_face || k == 0) ? 1 : 2 * k) {
          visitKey(own[0] + dx, own[1] + dy, own[2] + dz);
        }
      }
    }
  }
}

std::optional<Neighbour> VoxelHashMap::nearest(const Point& query, double max_distance) const {
  if (!(max_distance >= 0.0) || voxels_.empty()) return std::nullopt;
  double best_sq = max_distance * max_distance;
  const Point* best_point = nullptr;
  const Normal* best_normal = nullptr;
  visitVoxels(query, max_distance, [&](const Voxel& voxel) {
    for (const Point& point : voxel.points) {
      const double distance_sq = (point - query).squaredNorm();
      if (distance_sq <= best_sq) {
        best_sq = distance_sq;
        best_point = &point;
        best_normal = &voxel.normal;
      }
    }
    return std::sqrt(best_sq);
  });
  if (best_point == nullptr) return std::nullopt;
  return Neighbour{*best_point, *best_normal, std::sqrt(best_sq)};
}

std::vector<Point> VoxelHashMap::within(const Point& query, double radius) const {
  std::vector<Point> found;
  if (!(radius >= 0.0)) return found;
  const double radius_sq = radius * radius;
  visitVoxels(query, radius, [&](const Voxel& voxel) {
    for (const Point& point : voxel.points) {
      if ((point - query).squaredNorm() <= radius_sq) found.push_back(point);
    }
    return radius;
  });
  return found;
}

void VoxelHashMap::estimateNormals(const NormalConfig& config) {
  // The voxels that gained points, in a flat list so the loop can be parallel; each
  // writes only its own normal, so the result does not depend on the thread count.
  std::vector<Voxel*> dirty;
  for (auto& [key, voxel] : voxels_) {
    if (voxel.dirty) dirty.push_back(&voxel);
  }
  const long count = static_cast<long>(dirty.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (long n = 0; n < count; ++n) {
    Voxel& voxel = *dirty[static_cast<std::size_t>(n)];
    Point centre = Point::Zero();
    for (const Point& point : voxel.points) centre += point;
    centre /= static_cast<double>(voxel.points.size());
    Moments moments;
    moments.reference = centre;
    const double radius_sq = config.radius * config.radius;
    visitVoxels(centre, config.radius, [&](const Voxel& neighbour) {
      for (const Point& point : neighbour.points) {
        if ((point - centre).squaredNorm() <= radius_sq) moments.add(point);
      }
      return config.radius;
    });
    voxel.normal = planeNormal(moments, config);
  }
  for (Voxel* voxel : dirty) voxel->dirty = false;
}

std::vector<Point> VoxelHashMap::points() const {
  std::vector<Point> all;
  all.reserve(size_);
  for (const auto& [key, voxel] : voxels_) all.insert(all.end(), voxel.points.begin(), voxel.points.end());
  return all;
}

}  // namespace mlmap::registration
