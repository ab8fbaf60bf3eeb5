#include "edge_choice.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mlmap {
namespace {

// A patch's heights in bins of this (or its tolerance).
constexpr double kHeightBin = 0.02;

// Height bins of one patch at most (2 km at 2 cm).
constexpr double kMaxHeightBins = 1e5;

// σ of a normal distribution from the median of its absolute values.
constexpr double kMadToSigma = 1.4826;

}  // namespace

std::vector<double> alongTolerances(std::span<const Point> points, std::span<const std::uint32_t> slot_of_point,
                                    const std::vector<PointPlane>& fitted,
                                    const std::function<Eigen::Vector3d(std::size_t)>& beam_of, double sigmas) {
  const std::size_t slots = fitted.size();
  std::vector<double> tolerance(slots, std::numeric_limits<double>::infinity());
  std::vector<std::vector<float>> offsets(slots);
  for (std::size_t index = 0; index < points.size(); ++index) {
    const std::uint32_t slot = slot_of_point[index];
    if (slot == 0) continue;
    const PointPlane& plane = fitted[slot];
    const double signed_distance = plane.normal.dot(points[index]) + plane.offset;
    const double along = plane.normal.dot(beam_of(index));
    if (!(std::abs(signed_distance) <= plane.tolerance) || !(std::abs(along) >= kMinIncidenceCosine)) continue;
    offsets[slot].push_back(static_cast<float>(std::abs(signed_distance / along)));
  }
  for (std::size_t slot = 1; slot < slots; ++slot) {
    std::vector<float>& o = offsets[slot];
    if (o.size() < 3) continue;
    std::nth_element(o.begin(), o.begin() + static_cast<std::ptrdiff_t>(o.size() / 2), o.end());
    tolerance[slot] = std::max(fitted[slot].tolerance, sigmas * kMadToSigma * o[o.size() / 2]);
  }
  return tolerance;
}

std::vector<HeightRange> patchHeights(std::span<const Point> points, std::span<const std::uint32_t> sole,
                                      const std::vector<PointPlane>& fitted, double min_width) {
  const std::size_t slots = fitted.size();
  struct Bin {  // how far along the patch (horizontally) a bin's points lie
    float low = std::numeric_limits<float>::infinity();
    float high = -std::numeric_limits<float>::infinity();
  };
  std::vector<std::vector<Bin>> bins(slots);
  std::vector<float> base(slots, std::numeric_limits<float>::infinity());
  std::vector<Eigen::Vector3d> across(slots, Eigen::Vector3d::UnitX());
  for (std::size_t slot = 1; slot < slots; ++slot) {
    const Eigen::Vector3d horizontal = fitted[slot].normal.cross(Eigen::Vector3d::UnitZ());
    if (horizontal.norm() > 0.1) across[slot] = horizontal.normalized();
  }
  for (std::size_t index = 0; index < points.size(); ++index)
    if (sole[index] != 0 && std::isfinite(points[index].z()))
      base[sole[index]] = std::min(base[sole[index]], static_cast<float>(points[index].z()));
  const auto binWidth = [&](std::size_t slot) { return std::max(kHeightBin, fitted[slot].tolerance); };
  for (std::size_t index = 0; index < points.size(); ++index) {
    const std::uint32_t slot = sole[index];
    if (slot == 0) continue;
    const double offset = (points[index].z() - base[slot]) / binWidth(slot);
    // A patch's own points lie within its blocks' heights: more bins than this are no patch.
    if (!(offset >= 0.0 && offset < kMaxHeightBins)) continue;
    const auto n = static_cast<std::size_t>(offset);
    if (n >= bins[slot].size()) bins[slot].resize(n + 1);
    const auto u = static_cast<float>(across[slot].dot(points[index]));
    bins[slot][n].low = std::min(bins[slot][n].low, u);
    bins[slot][n].high = std::max(bins[slot][n].high, u);
  }
  std::vector<HeightRange> heights(slots);
  for (std::size_t slot = 1; slot < slots; ++slot) {
    std::size_t first = bins[slot].size(), last = 0;
    for (std::size_t n = 0; n < bins[slot].size(); ++n) {
      if (!(bins[slot][n].high - bins[slot][n].low >= min_width)) continue;
      first = std::min(first, n);
      last = n;
    }
    if (first > last) continue;  // nowhere wide: unknown, it decides no edge
    const double bin = binWidth(slot);
    const double slack = bin + 2.0 * fitted[slot].tolerance;
    heights[slot].low = static_cast<float>(base[slot] + static_cast<double>(first) * bin - slack);
    heights[slot].high = static_cast<float>(base[slot] + static_cast<double>(last + 1) * bin + slack);
  }
  return heights;
}

}  // namespace mlmap
