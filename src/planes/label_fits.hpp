// Internal to the labels (point_labels.cpp): the planes of a map's patches refitted to
// the points labelled with them — their moments summed per patch, the least-squares plane
// and its tolerance, and whether a fit of a patch's inner points turns it significantly.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "mlmap/planes/point_labels.hpp"
#include "mlmap/scan.hpp"
#include "pca_sums.hpp"

namespace mlmap {

// Point chunks of a fixed count, summed in chunk order: the same sums, bit for bit,
// whatever the thread count.
inline constexpr std::int64_t kLabelChunks = 64;

// Per slot (slot_of_point; 0: none), the moments about origin[slot] of the points that
// `accept(slot, index)` takes.
template <typename Accept>
std::vector<PcaSums> labelledMoments(std::span<const Point> points, std::span<const std::uint32_t> slot_of_point,
                                     const std::vector<Eigen::Vector3d>& origin, Accept&& accept) {
  const std::size_t slots = origin.size();
  std::vector<std::vector<PcaSums>> per_chunk(kLabelChunks);
  const auto count = static_cast<std::int64_t>(points.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t chunk = 0; chunk < kLabelChunks; ++chunk) {
    std::vector<PcaSums>& moments = per_chunk[static_cast<std::size_t>(chunk)];
    moments.assign(slots, PcaSums{});
    const std::int64_t begin = count * chunk / kLabelChunks;
    const std::int64_t end = count * (chunk + 1) / kLabelChunks;
    for (std::int64_t k = begin; k < end; ++k) {
      const auto index = static_cast<std::size_t>(k);
      const std::uint32_t slot = slot_of_point[index];
      if (slot == 0 || !accept(slot, index)) continue;
      moments[slot].add(points[index] - origin[slot], 1.0);
    }
  }
  std::vector<PcaSums> total(slots);
  for (const auto& moments : per_chunk)
    for (std::size_t slot = 0; slot < slots; ++slot) total[slot].addShifted(moments[slot], Eigen::Vector3d::Zero());
  return total;
}

// At most this many points of a patch for its robust statistics (ownNoise, PatchSides): a
// median or a share of that many is within a percent or two, and a cloud of tens of
// millions of points needs no copy of them.
inline constexpr std::size_t kPatchSample = 20000;

// `visit(index, slot)` for every k-th point of each patch (slot_of_point; 0: none, and
// slots from `slots` on are ignored), k from its count so that at most `sample` of them
// come, in index order.
template <typename Visit>
void forSampledPoints(std::span<const std::uint32_t> slot_of_point, std::size_t slots, std::size_t sample,
                      Visit&& visit) {
  std::vector<std::size_t> count(slots, 0);
  for (const std::uint32_t slot : slot_of_point)
    if (slot < slots) ++count[slot];
  std::vector<std::size_t> seen(slots, 0);
  for (std::size_t index = 0; index < slot_of_point.size(); ++index) {
    const std::uint32_t slot = slot_of_point[index];
    if (slot == 0 || slot >= slots || seen[slot]++ % std::max<std::size_t>(1, count[slot] / sample) != 0) continue;
    visit(index, slot);
  }
}

// The least-squares plane of the moments, its tolerance from the points' RMS distance;
// `plane` stays as it is where the moments hold fewer than 3 points.
void fitLabelledPlane(const PcaSums& moments, const Eigen::Vector3d& origin, const PointLabelRefinement& options,
                      PointPlane& plane);

// Per slot (slot_of_point; 0: none), the robust σ of its points' signed distances from
// planes[slot], of those within `band` of it (0: all): 1.4826 × their median absolute
// deviation from their median (σ for Gaussian noise, unmoved by a minority of outliers
// and by a plane a few millimetres off); 0 where fewer than 3 points.
std::vector<double> ownNoise(std::span<const Point> points, std::span<const std::uint32_t> slot_of_point,
                             const std::vector<PointPlane>& planes, double band);

// Whether a fit of few inner points turns the plane (normal `before` -> `after`)
// significantly (label_fits.cpp).
bool innerFitHolds(const PcaSums& inner, const Eigen::Vector3d& before, const Eigen::Vector3d& after);

}  // namespace mlmap
