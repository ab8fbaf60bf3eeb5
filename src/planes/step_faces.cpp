#include "step_faces.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "crease_faces.hpp"
#include "mlmap/planes/classify.hpp"

namespace mlmap {
namespace {

// The most of the smaller face's blocks that may lie on the larger's stretch of the wall:
// a fifth (its rim, where the two faces' cells meet); a depth camera's layers of one wall
// lie over each other all along it.
constexpr double kMaxSharedStretch = 0.2;
// Two groups, not one spread: their means this many times their blocks' scatter about them
// apart. The best cut of one normal spread into two leaves them 2.7 times apart; of two
// faces a step apart, each its noise thick, many more (fr079's faces 7-9 cm apart with half
// their points at 10 cm cells: 6.3).
constexpr double kMinSeparation = 4.0;
// A face holds at least this share of the patch's points. A wall's noise tail beyond a cell
// boundary leaves single-point blocks a few σ in front of it, as tight a group as a face
// (the simulated corridor at 10 cm cells: 12 blocks of one point each, 2.5 cm before an end
// wall of 3,400 points); fr079's lower faces hold 30-40 % of their walls' points.
constexpr double kMinFaceShare = 0.1;

// The share of `smaller`'s blocks whose points' mean lies on `larger`'s stretch of the
// wall: within a cell along it of a block of `larger` whose height spans that mean. By the
// means, not the blocks' extents: a face's noise tail beyond a cell boundary puts a few
// points of the other face in its cells, which then reach over the other face's heights.
double sharedStretch(const BlockGrid& grid, const std::vector<std::uint32_t>& smaller,
                     const std::vector<std::uint32_t>& larger, const Eigen::Vector3d& along) {
  if (smaller.empty()) return 1.0;
  const double cell = grid.cellSize();
  const auto meanOf = [&](std::uint32_t id) -> Eigen::Vector3d { return grid.pointsFrameOf(id) + grid.pointsOf(id).mean(); };
  // The larger face's blocks by their place along the wall: (along, bottom, top).
  struct Span {
    double along = 0.0;
    double bottom = 0.0;
    double top = 0.0;
  };
  std::vector<Span> spans;
  spans.reserve(larger.size());
  for (const std::uint32_t id : larger) {
    const PlaneBlock& block = grid.blocks()[id];
    spans.push_back({along.dot(meanOf(id)), block.vertical ? block.bottom : block.point.z() - 0.5 * cell,
                     block.vertical ? block.top : block.point.z() + 0.5 * cell});
  }
  std::sort(spans.begin(), spans.end(), [](const Span& a, const Span& b) { return a.along < b.along; });
  std::size_t shared = 0;
  for (const std::uint32_t id : smaller) {
    const Eigen::Vector3d p = meanOf(id);
    const double at = along.dot(p);
    auto span = std::lower_bound(spans.begin(), spans.end(), at - cell,
                                 [](const Span& s, double value) { return s.along < value; });
    for (; span != spans.end() && span->along <= at + cell; ++span) {
      if (p.z() >= span->bottom && p.z() <= span->top) {
        ++shared;
        break;
      }
    }
  }
  return static_cast<double>(shared) / static_cast<double>(smaller.size());
}

}  // namespace

std::vector<std::vector<std::size_t>> stepFaces(const BlockGrid& grid, const PatchSet& set, std::size_t k,
                                                const CreaseConfig& config) {
  const Plane& plane = set.planes[k];
  const std::vector<std::uint32_t>& blocks = set.blocks[k];
  if (!isPlumb(plane.normal) || config.noise <= 0.0) return {};
  const Eigen::Vector3d across = Eigen::Vector3d(plane.normal.x(), plane.normal.y(), 0.0).normalized();
  const Eigen::Vector3d along(-across.y(), across.x(), 0.0);
  // Each block's points' mean across the wall, weighted by its points.
  struct Across {
    double offset = 0.0;
    double weight = 0.0;
    std::size_t index = 0;
  };
  std::vector<Across> samples;
  samples.reserve(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const PointStats stats = grid.pointsOf(blocks[b]);
    if (stats.empty()) return {};  // a map without point moments
    samples.push_back({across.dot(grid.pointsFrameOf(blocks[b]) + stats.mean()), static_cast<double>(stats.count), b});
  }
  std::sort(samples.begin(), samples.end(), [](const Across& a, const Across& b) { return a.offset < b.offset; });
  // The two groups that leave the least weighted scatter (one pass over the sorted offsets).
  double total_w = 0.0, total_wo = 0.0, total_woo = 0.0;
  for (const Across& s : samples) {
    total_w += s.weight;
    total_wo += s.weight * s.offset;
    total_woo += s.weight * s.offset * s.offset;
  }
  double best_left = std::numeric_limits<double>::infinity();
  std::size_t best_cut = 0;  // the first group: samples [0, best_cut), of weight first_w
  double first_w = 0.0, first_wo = 0.0;
  double w = 0.0, wo = 0.0, woo = 0.0;
  for (std::size_t cut = 1; cut < samples.size(); ++cut) {
    w += samples[cut - 1].weight;
    wo += samples[cut - 1].weight * samples[cut - 1].offset;
    woo += samples[cut - 1].weight * samples[cut - 1].offset * samples[cut - 1].offset;
    const double rest_w = total_w - w;
    if (w <= 0.0 || rest_w <= 0.0) continue;
    const double left = (woo - wo * wo / w) + ((total_woo - woo) - (total_wo - wo) * (total_wo - wo) / rest_w);
    if (left < best_left) {
      best_left = left;
      best_cut = cut;
      first_w = w;
      first_wo = wo;
    }
  }
  if (best_cut == 0) return {};
  const double step = 3.0 * std::numbers::sqrt2 * config.noise;
  const double apart = (total_wo - first_wo) / (total_w - first_w) - first_wo / first_w;
  const double scatter = std::sqrt(std::max(0.0, best_left) / total_w);
  if (apart < step || apart < kMinSeparation * scatter) return {};
  if (std::min(first_w, total_w - first_w) < kMinFaceShare * total_w) return {};
  std::vector<std::vector<std::size_t>> faces(2);
  std::vector<std::vector<std::uint32_t>> ids(2);
  for (std::size_t s = 0; s < samples.size(); ++s) {
    const std::size_t face = s < best_cut ? 0 : 1;
    faces[face].push_back(samples[s].index);
    ids[face].push_back(blocks[samples[s].index]);
  }
  for (std::size_t f = 0; f < 2; ++f) {
    std::sort(faces[f].begin(), faces[f].end());
    std::sort(ids[f].begin(), ids[f].end());
    if (tooSmallForFace(ids[f].size(), surfaceOf(grid, ids[f]), grid.cellSize(), config)) return {};
  }
  const bool first_smaller = ids[0].size() <= ids[1].size();
  if (sharedStretch(grid, ids[first_smaller ? 0 : 1], ids[first_smaller ? 1 : 0], along) > kMaxSharedStretch) return {};
  return faces;
}

}  // namespace mlmap
