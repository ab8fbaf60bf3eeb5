#include "plane_scorer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace mlmap {
namespace {

constexpr int kElevationRows = 9;     // 10° each over [0°, 90°]
constexpr int kAzimuthColumns = 36;   // 10° each over the full circle
constexpr double kBinRadius = 7.1 * std::numbers::pi / 180.0;  // half the diagonal of a 10° bin

int binOf(const Eigen::Vector3f& direction) {
  // Unsigned axes: use the upper hemisphere's representative.
  const Eigen::Vector3f axis = direction.z() < 0.0F ? Eigen::Vector3f(-direction) : direction;
  const double elevation = std::asin(std::min(1.0F, axis.z()));
  double azimuth = std::atan2(axis.y(), axis.x());
  if (azimuth < 0.0) azimuth += 2.0 * std::numbers::pi;
  const int row = std::min(kElevationRows - 1, static_cast<int>(elevation / (std::numbers::pi / 2) * kElevationRows));
  const int column = std::min(kAzimuthColumns - 1, static_cast<int>(azimuth / (2 * std::numbers::pi) * kAzimuthColumns));
  return row * kAzimuthColumns + column;
}

}  // namespace

PlaneScorer::PlaneScorer(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                         double epsilon, double kappa_rad)
    : grid_(grid),
      directions_(directions),
      epsilon_(static_cast<float>(epsilon)),
      cos_kappa_(static_cast<float>(std::cos(kappa_rad))),
      cos_bin_reach_(static_cast<float>(std::cos(std::min(kappa_rad + kBinRadius, std::numbers::pi / 2)))),
      bins_(kElevationRows * kAzimuthColumns),
      taken_(grid.size(), 0) {
  for (int row = 0; row < kElevationRows; ++row) {
    for (int column = 0; column < kAzimuthColumns; ++column) {
      const double elevation = (row + 0.5) * (std::numbers::pi / 2) / kElevationRows;
      const double azimuth = (column + 0.5) * 2 * std::numbers::pi / kAzimuthColumns;
      bins_[static_cast<std::size_t>(row * kAzimuthColumns + column)].axis =
          Eigen::Vector3f(static_cast<float>(std::cos(elevation) * std::cos(azimuth)),
                          static_cast<float>(std::cos(elevation) * std::sin(azimuth)),
                          static_cast<float>(std::sin(elevation)));
    }
  }
  slot_.assign(grid.size(), {UINT32_MAX, 0});
  for (std::uint32_t id = 0; id < grid.size(); ++id) {
    if (directions[id].squaredNorm() == 0.0F) continue;
    const auto bin_number = static_cast<std::uint32_t>(binOf(directions[id]));
    Bin& bin = bins_[bin_number];
    const PlaneBlock& block = grid.blocks()[id];
    slot_[id] = {bin_number, static_cast<std::uint32_t>(bin.ids.size())};
    bin.ids.push_back(id);
    bin.points.push_back(block.point);
    bin.directions.push_back(directions[id]);
    bin.surfaces.push_back(block.surface);
    bin.half_depths.push_back(block.vertical ? 0.5F * (block.top - block.bottom) : 0.0F);
    bin.taken.push_back(0);
  }
}

template <typename Visit>
void PlaneScorer::forEachSimilar(const CandidatePlane& plane, Visit&& visit) const {
  for (const Bin& bin : bins_) {
    if (bin.ids.empty() || std::abs(bin.axis.dot(plane.normal)) < cos_bin_reach_) continue;
    const std::size_t count = bin.ids.size();
    for (std::size_t k = 0; k < count; ++k) {
      if (bin.taken[k] != 0) continue;
      if (std::abs(bin.directions[k].dot(plane.normal)) < cos_kappa_) continue;
      visit(bin, k);
    }
  }
}

PlaneScore PlaneScorer::score(const CandidatePlane& plane) const {
  PlaneScore result;
  const float offset = -plane.normal.dot(plane.point);
  forEachSimilar(plane, [&](const Bin& bin, std::size_t k) {
    const float surface = bin.surfaces[k];
    result.similar += surface;
    if (std::abs(plane.normal.dot(bin.points[k]) + offset) >= epsilon_) return;
    result.score += surface;
    result.pca.addBlock((bin.points[k] - plane.point).cast<double>(), bin.half_depths[k], surface);
  });
  return result;
}

bool PlaneScorer::matches(std::uint32_t id, const CandidatePlane& plane) const {
  if (taken_[id] != 0 || directions_[id].squaredNorm() == 0.0F) return false;
  if (std::abs(directions_[id].dot(plane.normal)) < cos_kappa_) return false;
  return std::abs(plane.normal.dot(grid_.blocks()[id].point - plane.point)) < epsilon_;
}

std::vector<std::uint32_t> PlaneScorer::matching(const CandidatePlane& plane) const {
  std::vector<std::uint32_t> ids;
  const float offset = -plane.normal.dot(plane.point);
  forEachSimilar(plane, [&](const Bin& bin, std::size_t k) {
    if (std::abs(plane.normal.dot(bin.points[k]) + offset) < epsilon_) ids.push_back(bin.ids[k]);
  });
  std::sort(ids.begin(), ids.end());
  return ids;
}

void PlaneScorer::take(std::uint32_t id) {
  taken_[id] = 1;
  const auto [bin, index] = slot_[id];
  if (bin != UINT32_MAX) bins_[bin].taken[index] = 1;
}

}  // namespace mlmap
