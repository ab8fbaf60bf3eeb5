#include "mlmap/planes/point_labels.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace mlmap {

std::vector<std::int32_t> labelPoints(const MLMap& map, const Scan& scan) {
  std::vector<std::int32_t> labels(scan.size(), -1);
  const double reach = map.cellSize();
  const auto count = static_cast<std::int64_t>(scan.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < count; ++k) {
    const auto index = static_cast<std::size_t>(k);
    const Point p = scan.worldPoint(index);
    // Points without a cell get no label (cellOf would throw inside the parallel loop).
    const auto cell = map.findCellOf(p.x(), p.y());
    if (!cell || !std::isfinite(p.z())) continue;
    double best = std::numeric_limits<double>::infinity();
    for (const Block& block : map.blocks(*cell)) {
      const double distance = p.z() > block.height ? p.z() - block.height
                              : p.z() < block.bottom() ? block.bottom() - p.z()
                                                       : 0.0;
      if (distance < reach && distance < best) {
        best = distance;
        labels[index] = block.plane;
      }
    }
  }
  return labels;
}

namespace {

// Ids come from a map file: anything outside 1..kMaxPlaneId is treated as "none".
constexpr std::int32_t kMaxPlaneId = 1 << 24;

// Moments of a patch's points about a fixed origin (its detected centroid), so the
// covariance keeps its precision far from the world origin.
struct Moments {
  double count = 0.0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();

  void add(const Eigen::Vector3d& q) {
    count += 1.0;
    sum += q;
    outer += q * q.transpose();
  }
  void add(const Moments& other) {
    count += other.count;
    sum += other.sum;
    outer += other.outer;
  }
};

// Point chunks of a fixed count, summed in chunk order: the same sums, bit for bit,
// whatever the thread count.
constexpr std::int64_t kChunks = 256;

template <typename Accept>
std::vector<Moments> patchMoments(std::span<const Point> points, std::span<const std::int32_t> labels,
                                  const std::vector<Eigen::Vector3d>& origin, Accept&& accept) {
  const std::size_t slots = origin.size();
  std::vector<std::vector<Moments>> per_chunk(kChunks);
  const auto count = static_cast<std::int64_t>(points.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t chunk = 0; chunk < kChunks; ++chunk) {
    std::vector<Moments>& moments = per_chunk[static_cast<std::size_t>(chunk)];
    moments.assign(slots, Moments{});
    const std::int64_t begin = count * chunk / kChunks;
    const std::int64_t end = count * (chunk + 1) / kChunks;
    for (std::int64_t k = begin; k < end; ++k) {
      const auto index = static_cast<std::size_t>(k);
      const std::int32_t label = labels[index];
      if (label <= 0 || static_cast<std::size_t>(label) >= slots) continue;
      if (!accept(label, points[index])) continue;
      moments[static_cast<std::size_t>(label)].add(points[index] - origin[static_cast<std::size_t>(label)]);
    }
  }
  std::vector<Moments> total(slots);
  for (const auto& moments : per_chunk)
    for (std::size_t slot = 0; slot < slots; ++slot) total[slot].add(moments[slot]);
  return total;
}

// The least-squares plane of the moments, its tolerance from the points' RMS distance.
void fitPlane(const Moments& moments, const Eigen::Vector3d& origin, const PointLabelRefinement& options,
              PointPlane& plane) {
  if (moments.count < 3.0) return;  // keep the detected plane
  const Eigen::Vector3d mean = moments.sum / moments.count;
  const Eigen::Matrix3d covariance = moments.outer / moments.count - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  if (solver.info() != Eigen::Success) return;
  Eigen::Vector3d normal = solver.eigenvectors().col(0);
  if (!normal.allFinite()) return;
  if (normal.dot(plane.normal) < 0.0) normal = -normal;  // keep the detected orientation
  const double rms = std::sqrt(std::max(0.0, solver.eigenvalues()(0)));
  plane.normal = normal;
  plane.offset = -normal.dot(origin + mean);
  // A patch's own RMS grows with the points of neighbouring surfaces that its blocks
  // collected (a table's rim): the sensor's noise, when known, caps it.
  const double sigma = options.noise > 0.0 ? std::min(rms, options.noise) : rms;
  plane.tolerance = std::max(options.min_tolerance, options.sigmas * sigma);
  plane.points = static_cast<std::size_t>(moments.count);
}

double planeDistance(const PointPlane& plane, const Point& p) {
  return std::abs(plane.normal.dot(p) + plane.offset);
}

}  // namespace

std::vector<PointPlane> refinePointLabels(const MLMap& map, std::span<const Plane> planes,
                                          std::span<const Point> points, std::span<std::int32_t> labels,
                                          const PointLabelRefinement& options) {
  std::int32_t max_id = 0;
  for (const Plane& plane : planes)
    if (plane.id > 0 && plane.id <= kMaxPlaneId) max_id = std::max(max_id, plane.id);
  const auto slots = static_cast<std::size_t>(max_id) + 1;
  std::vector<PointPlane> fitted(slots);
  std::vector<bool> known(slots, false);
  std::vector<Eigen::Vector3d> origin(slots, Eigen::Vector3d::Zero());
  for (const Plane& plane : planes) {
    if (plane.id <= 0 || plane.id > kMaxPlaneId) continue;
    const auto slot = static_cast<std::size_t>(plane.id);
    known[slot] = true;
    origin[slot] = plane.centroid.allFinite() ? plane.centroid : Eigen::Vector3d::Zero();
    fitted[slot].normal = plane.normal.allFinite() && plane.normal.norm() > 0.0 ? plane.normal.normalized()
                                                                               : Eigen::Vector3d::UnitZ();
    fitted[slot].offset = std::isfinite(plane.offset) ? plane.offset : 0.0;
    const double rms = std::isfinite(plane.rms) ? plane.rms : 0.0;
    const double sigma = options.noise > 0.0 ? std::min(rms, options.noise) : rms;
    fitted[slot].tolerance = std::max(options.min_tolerance, options.sigmas * sigma);
  }
  // Labels of unknown patches are "none" from here on.
  for (std::int32_t& label : labels)
    if (label > 0 && (label > max_id || !known[static_cast<std::size_t>(label)])) label = 0;

  // Two refits, each from the points near the previous plane: the detected one, then
  // the first fit. The points of a neighbouring surface that the blocks collected
  // would tilt a fit of all of them.
  for (const double first_band : {options.band, -1.0}) {
    const std::vector<PointPlane> previous = fitted;
    const auto near_previous = [&previous, first_band](std::int32_t label, const Point& p) {
      const PointPlane& plane = previous[static_cast<std::size_t>(label)];
      const double band = first_band < 0.0 ? plane.tolerance : first_band;
      return band == 0.0 || planeDistance(plane, p) <= band;
    };
    const std::vector<Moments> moments = patchMoments(points, labels, origin, near_previous);
    for (std::size_t slot = 1; slot < slots; ++slot) fitPlane(moments[slot], origin[slot], options, fitted[slot]);
  }

  const double reach = map.cellSize();
  const auto count = static_cast<std::int64_t>(points.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < count; ++k) {
    const auto index = static_cast<std::size_t>(k);
    const Point& p = points[index];
    std::int32_t& label = labels[index];
    // Near an edge a point lies within tolerance of two planes: the more likely one
    // wins, i.e. the smaller distance in units of the plane's own spread (a floor seen
    // at a grazing angle is far thinner than a wall seen head on), the collecting
    // block's patch first among equals.
    std::int32_t best_label = label < 0 ? -1 : 0;
    double best = std::numeric_limits<double>::infinity();
    if (label > 0) {
      const PointPlane& own = fitted[static_cast<std::size_t>(label)];
      const double distance = planeDistance(own, p) / own.tolerance;
      if (distance <= 1.0) {
        best = distance;
        best_label = label;
      }
    }
    const auto cell = map.findCellOf(p.x(), p.y());
    if (cell && p.allFinite()) {
      for (std::int32_t di = -1; di <= 1; ++di) {
        for (std::int32_t dj = -1; dj <= 1; ++dj) {
          for (const Block& block : map.blocks(CellIndex{cell->i + di, cell->j + dj})) {
            if (block.plane <= 0 || block.plane > max_id || !known[static_cast<std::size_t>(block.plane)]) continue;
            if (p.z() > block.height + reach || p.z() < block.bottom() - reach) continue;
            const PointPlane& plane = fitted[static_cast<std::size_t>(block.plane)];
            const double distance = planeDistance(plane, p) / plane.tolerance;
            if (distance <= 1.0 && distance < best) {
              best = distance;
              best_label = block.plane;
            }
          }
        }
      }
    }
    label = best_label;
  }
  return fitted;
}

}  // namespace mlmap
