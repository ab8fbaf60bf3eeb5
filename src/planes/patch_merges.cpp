#include "patch_merges.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "median.hpp"
#include "mlmap/planes/classify.hpp"
#include "piece_tests.hpp"
#include "seen_gaps.hpp"

namespace mlmap {
namespace {

// Merges the planes that share a root (the root's index is the smallest of its
// group); ids are renumbered in order and the block labels follow.
void mergeGroups(const BlockGrid& grid, PatchSet& set, const std::vector<std::size_t>& roots, double kappa_rad,
                 double noise) {
  const std::vector<Plane>& planes = set.planes;
  const std::size_t count = planes.size();
  std::vector<Plane> merged;
  std::vector<std::vector<std::uint32_t>> merged_blocks;
  std::vector<OutlineFrame> merged_frames;
  std::vector<std::vector<Segment>> merged_runs;
  std::vector<std::int32_t> new_id(count, 0);
  for (std::size_t k = 0; k < count; ++k) {
    if (roots[k] != k) continue;
    std::size_t members = 0;
    for (std::size_t member = 0; member < count; ++member) members += roots[member] == k ? 1 : 0;
    Plane plane;
    Patch patch;
    OutlineFrame frame;
    std::vector<Segment> runs;
    if (members == 1) {
      plane = planes[k];  // alone: as it was
      patch.blocks = std::move(set.blocks[k]);
      frame = set.outline_frames[k];
      runs = std::move(set.outline_runs[k]);
    } else {
      // Each member's blocks are ascending: merged, not sorted again.
      for (std::size_t member = 0; member < count; ++member) {
        if (roots[member] != k) continue;
        const auto middle = static_cast<std::ptrdiff_t>(patch.blocks.size());
        patch.blocks.insert(patch.blocks.end(), set.blocks[member].begin(), set.blocks[member].end());
        std::inplace_merge(patch.blocks.begin(), patch.blocks.begin() + middle, patch.blocks.end());
      }
      // The group's reference is its root (the first in order, as the search accepted them),
      // unless the root leans from the largest member by more than κ / 2: a strip a few
      // blocks wide that joined leaning (withinSheet) can come first, and a wall described
      // on its 35° lean kept a fifth of its blocks (held-out office-14 at 3 cm of noise).
      // Not the largest always: the outline of a desk's side panel and the monitor's face
      // above it, one plane, described on the monitor's piece, rose above the desk's top.
      std::size_t largest_member = k;
      for (std::size_t member = k; member < count; ++member)
        if (roots[member] == k && set.blocks[member].size() > set.blocks[largest_member].size()) largest_member = member;
      const bool root_leans =
          std::abs(planes[k].normal.dot(planes[largest_member].normal)) < std::cos(0.5 * kappa_rad);
      const Plane& described_on = planes[root_leans ? largest_member : k];
      const CandidatePlane reference{described_on.normal.cast<float>(), described_on.centroid.cast<float>()};
      patch.surface = surfaceOf(grid, patch.blocks);
      frame = OutlineFrame{described_on.normal, described_on.centroid, true};
      plane = describePatch(grid, patch, reference, kappa_rad, noise);
      plane.source = described_on.source;
      plane.candidates = described_on.candidates;
      plane.label = described_on.label;
    }
    plane.id = static_cast<std::int32_t>(merged.size() + 1);
    for (std::size_t member = 0; member < count; ++member) {
      if (roots[member] == k) new_id[member] = plane.id;
    }
    merged.push_back(std::move(plane));
    merged_blocks.push_back(std::move(patch.blocks));
    merged_frames.push_back(frame);
    merged_runs.push_back(std::move(runs));
  }
  set.planes = std::move(merged);
  set.blocks = std::move(merged_blocks);
  set.outline_frames = std::move(merged_frames);
  set.outline_runs = std::move(merged_runs);
  for (std::int32_t& label : set.labels) {
    if (label > 0) label = new_id[static_cast<std::size_t>(label - 1)];
  }
}

// A patch's points' moments about `origin` (a map's cell centre at z 0): patches' moments
// about one origin add up to their union's.
PointMoments patchMoments(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Eigen::Vector3d& origin) {
  PointMoments points;
  for (const std::uint32_t id : blocks) {
    points.add(grid.pointsOf(id), grid.pointsFrameOf(id) - origin);
  }
  return points;
}

PointMoments sum(PointMoments first, const PointMoments& second) {
  first.merge(second);
  return first;
}

// The RMS distance of points from their least-squares plane; nullopt for fewer than 3.
std::optional<double> planeRms(const PointMoments& points) {
  if (points.count < 3.0) return std::nullopt;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(points.covariance(), Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, solver.eigenvalues()(0)));
}

struct CellBox {
  std::int32_t min_i = std::numeric_limits<std::int32_t>::max();
  std::int32_t max_i = std::numeric_limits<std::int32_t>::min();
  std::int32_t min_j = std::numeric_limits<std::int32_t>::max();
  std::int32_t max_j = std::numeric_limits<std::int32_t>::min();
};

// Whether a block of `first` and one of `second` lie within `radius` cells of each other
// (along both grid axes). Pairwise: a wall's pieces hold a few hundred cells each, and a
// window a door wide would visit (2 radius + 1)² cells per block.
bool withinCells(const BlockGrid& grid, const std::vector<std::uint32_t>& first, const std::vector<std::uint32_t>& second,
                 int radius) {
  for (const std::uint32_t a : first) {
    const CellIndex p = grid.blocks()[a].cell;
    for (const std::uint32_t b : second) {
      const CellIndex q = grid.blocks()[b].cell;
      if (std::abs(p.i - q.i) <= radius && std::abs(p.j - q.j) <= radius) return true;
    }
  }
  return false;
}

}  // namespace

void mergeCoplanar(const BlockGrid& grid, PatchSet& set, double epsilon, double kappa_rad, double noise,
                   const std::vector<int>& families) {
  const std::vector<Plane>& planes = set.planes;
  const std::size_t count = planes.size();
  std::vector<std::size_t> group(count);
  for (std::size_t k = 0; k < count; ++k) group[k] = k;
  // Per group (at its root): the families of its members.
  std::vector<std::vector<int>> kept_apart(count);
  for (std::size_t k = 0; k < families.size() && k < count; ++k)
    if (families[k] >= 0) kept_apart[k].push_back(families[k]);
  auto root = [&](std::size_t k) {
    while (group[k] != k) k = group[k] = group[group[k]];
    return k;
  };
  const double cos_parallel = std::cos(0.5 * kappa_rad);
  // Each patch's points' moments, summed once when a pair first needs them; each group's
  // (at its root) once it has joined another.
  std::vector<std::optional<PointMoments>> moments(count);
  std::vector<std::optional<PointMoments>> group_moments(count);
  const Eigen::Vector3d origin = grid.size() > 0 ? grid.pointsFrameOf(0) : Eigen::Vector3d::Zero();
  const auto momentsOf = [&](std::size_t k) -> const PointMoments& {
    if (!moments[k]) moments[k] = patchMoments(grid, set.blocks[k], origin);
    return *moments[k];
  };
  const auto groupMomentsOf = [&](std::size_t group_root) -> const PointMoments& {
    return group_moments[group_root] ? *group_moments[group_root] : momentsOf(group_root);
  };
  const auto level = [](const Plane& plane) { return std::abs(plane.normal.z()) >= std::cos(std::numbers::pi / 4.0); };
  // Pieces closer than a table leg's width are one surface; a wall's pieces are one wall
  // across a doorway (a single door is under 1 m wide). 3DTK's hall: a wall's pieces either
  // side of doorways 0.45 and 0.6 m wide were two patches (58 % of it on one, 98 % joined);
  // no other real scan's marked surface and no simulated scene changed at 0.6 or 1 m.
  const int touch_radius = std::max(2, static_cast<int>(std::ceil(0.3 / grid.cellSize())));
  const int door_radius = std::max(touch_radius, static_cast<int>(std::ceil(1.0 / grid.cellSize())));
  const auto plumb = [](const Plane& plane) { return isPlumb(plane.normal); };
  std::vector<CellBox> boxes(count);
  for (std::size_t k = 0; k < count; ++k) {
    for (const std::uint32_t id : set.blocks[k]) {
      const CellIndex cell = grid.blocks()[id].cell;
      boxes[k].min_i = std::min(boxes[k].min_i, cell.i);
      boxes[k].max_i = std::max(boxes[k].max_i, cell.i);
      boxes[k].min_j = std::min(boxes[k].min_j, cell.j);
      boxes[k].max_j = std::max(boxes[k].max_j, cell.j);
    }
  }
  for (std::size_t a = 0; a < count; ++a) {
    for (std::size_t b = a + 1; b < count; ++b) {
      const Plane& first = planes[a];
      const Plane& second = planes[b];
      const double cosine = std::abs(first.normal.dot(second.normal));
      const bool parallel = cosine >= cos_parallel;
      // Leaning apart, not across: a riser's piece beside a tread is a face of its own.
      if (!parallel && (noise <= 0.0 || cosine < kMaxLeanCosine)) continue;
      // The smaller piece lies on the larger one's plane: its own fit is the less sure
      // (a few blocks' tilt puts the far centroid of a long wall well off it).
      const bool first_larger = set.blocks[a].size() >= set.blocks[b].size();
      const Plane& larger = first_larger ? first : second;
      const Plane& smaller = first_larger ? second : first;
      const double apart = std::abs(larger.normal.dot(smaller.centroid) + larger.offset);
      const bool both_plumb = plumb(first) && plumb(second);
      const int radius = both_plumb ? door_radius : touch_radius;
      if (boxes[a].min_i - radius > boxes[b].max_i || boxes[b].min_i - radius > boxes[a].max_i ||
          boxes[a].min_j - radius > boxes[b].max_j || boxes[b].min_j - radius > boxes[a].max_j) {
        continue;
      }
      if (!parallel && (std::min(set.blocks[a].size(), set.blocks[b].size()) * kStripShare >
                            std::max(set.blocks[a].size(), set.blocks[b].size()) ||
                        !withinSheet(momentsOf(first_larger ? b : a), larger, origin, noise, grid.cellSize())))
        continue;
      if (apart >= epsilon && !(noise > 0.0 && isNoiseTail(larger, apart)) &&
          !(noise > 0.0 && seamApart(grid, set, first_larger ? b : a, larger, touch_radius) < epsilon) &&
          !(noise > 0.0 && isSparseTail(grid, set, first_larger ? b : a, larger, apart, touch_radius))) {
        continue;
      }
      // Walk the smaller patch's neighbourhood looking for the larger one's label.
      const bool a_smaller = set.blocks[a].size() <= set.blocks[b].size();
      const auto& walked = set.blocks[a_smaller ? a : b];
      const std::int32_t wanted = (a_smaller ? second : first).id;
      // Level pieces near but not cell to cell are one surface where mostly nothing was
      // seen between them (an occluder's shadow), two where the scanner saw past them.
      const bool both_level = level(first) && level(second);
      const bool from_above = both_level && seenFromAbove(grid, set.blocks[a_smaller ? b : a], larger.normal,
                                                          larger.centroid, epsilon);
      bool touching = false;
      std::size_t clear = 0, through = 0;
      for (const std::uint32_t id : walked) {
        const CellIndex cell = grid.blocks()[id].cell;
        grid.forEachNeighbour(cell, touch_radius, [&](std::uint32_t other) {
          if (set.labels[other] != wanted || touching) return;
          const CellIndex near = grid.blocks()[other].cell;
          if (!from_above || std::max(std::abs(near.i - cell.i), std::abs(near.j - cell.j)) <= 1) {
            touching = true;
          } else if (seenPast(grid, larger.normal, larger.centroid, cell, near, epsilon)) {
            ++through;
          } else {
            ++clear;
          }
        });
        if (touching) break;
      }
      touching = touching || (clear > 0 && clear >= through);
      if (!touching && both_plumb) touching = withinCells(grid, walked, set.blocks[a_smaller ? b : a], door_radius);
      // Level pieces that meet cell to cell meet at one height: stair treads, each
      // fitted leaning towards its risers, pass the tests above at 10 cm cells (plane_seg's
      // ANYmal stairs: 8-19° off level) and chained into one ramp, though where they meet
      // their blocks differ by a riser (16.5 cm).
      if (touching && both_level) {
        std::vector<float> seam;
        for (const std::uint32_t id : walked) {
          const PlaneBlock& block = grid.blocks()[id];
          grid.forEachNeighbour(block.cell, 1, [&](std::uint32_t other) {
            if (set.labels[other] == wanted) seam.push_back(std::abs(grid.blocks()[other].point.z() - block.point.z()));
          });
        }
        if (!seam.empty() && medianOf(seam) > epsilon) touching = false;
      }
      // Two layers are one surface only within a sheet's step (3 √2 σ, sheets.hpp) of
      // each other: pieces that far apart, each a share w of the points, add at most
      // w (1 − w) step² ≤ step² / 4 to the larger's squared RMS about a joint plane. Further
      // apart they are two surfaces: OctoMap's fr079 at 10 cm cells, two walls 7 cm apart
      // (0.7 and 1.0 cm RMS, 3.5 cm together, σ 1.3 cm) were one. Layers of one surface stay
      // one: PCL's office1's far wall (a depth camera's steps, 0 and 2-2.5 cm RMS, σ 2 cm),
      // Bobkov's table (registered views, 2.3 and 3.3 cm, σ 1.9 cm). σ is the map's median;
      // where the pieces' own RMS is larger it speaks for their surface (the simulated lab at
      // 10 cm cells: walls 1 cm, σ read 0.4 cm).
      // Faces a patch was split into stay apart, also through a group either joined.
      if (touching && !families.empty()) {
        const std::vector<int>& mine = kept_apart[root(a)];
        const std::vector<int>& theirs = kept_apart[root(b)];
        touching = root(a) == root(b) || std::none_of(theirs.begin(), theirs.end(), [&](int v) {
                     return std::find(mine.begin(), mine.end(), v) != mine.end();
                   });
      }
      if (touching && noise > 0.0) {
        const auto oneSurface = [&](const PointMoments& one, const PointMoments& other, double own) {
          const std::optional<double> joint = planeRms(sum(one, other));
          return !joint || *joint <= oneSurfaceRms(noise, own);
        };
        touching = oneSurface(momentsOf(a), momentsOf(b), std::max(first.rms, second.rms));
        // The same test on the groups the two already joined: pairwise, a small rough piece
        // between a floor and a ramp passes with each and chains them into one patch
        // (tests/test_planes_merge_groups.cpp). Seen on OctoMap's fr079 at 10 cm cells when
        // the search accepted its planes in another order (a variant tried 2026-12-03): a
        // piece of 19 blocks, 4.7 cm RMS, joined the floor and the staircase, 7° off level.
        const std::size_t root_a = root(a), root_b = root(b);
        if (touching && root_a != root_b) {
          const PointMoments& group_a = groupMomentsOf(root_a);
          const PointMoments& group_b = groupMomentsOf(root_b);
          touching = oneSurface(group_a, group_b, std::max({first.rms, second.rms, planeRms(group_a).value_or(0.0),
                                                            planeRms(group_b).value_or(0.0)}));
          if (touching) group_moments[root_a] = sum(group_a, group_b);
        }
      }
      if (touching) {
        const std::size_t root_a = root(a), root_b = root(b);
        if (root_a != root_b) {
          std::vector<int>& mine = kept_apart[root_a];
          mine.insert(mine.end(), kept_apart[root_b].begin(), kept_apart[root_b].end());
          group[root_b] = root_a;
        }
      }
    }
  }
  std::vector<std::size_t> roots(count);
  for (std::size_t k = 0; k < count; ++k) roots[k] = root(k);
  mergeGroups(grid, set, roots, kappa_rad, noise);
}

void mergeLevels(const BlockGrid& grid, PatchSet& set, double kappa_rad, double noise,
                 std::vector<std::uint8_t>* landings) {
  const std::vector<Plane>& planes = set.planes;
  std::vector<std::size_t> roots(planes.size());
  const auto isLanding = [&](std::size_t k) { return landings != nullptr && k < landings->size() && (*landings)[k] != 0; };
  // A landing is floor at its own height: it joins no other floor.
  const auto mergesAsLevel = [&](std::size_t k) {
    return (planes[k].label == PlaneClass::Floor || planes[k].label == PlaneClass::Ceiling) && !isLanding(k);
  };
  for (std::size_t k = 0; k < planes.size(); ++k) {
    roots[k] = k;
    if (!mergesAsLevel(k)) continue;
    for (std::size_t first = 0; first < k; ++first) {
      if (planes[first].label == planes[k].label && mergesAsLevel(first)) {
        roots[k] = first;
        break;
      }
    }
  }
  // The merged planes are the roots, in order.
  std::vector<std::uint8_t> merged_landings;
  for (std::size_t k = 0; k < planes.size(); ++k)
    if (roots[k] == k) merged_landings.push_back(isLanding(k) ? 1 : 0);
  mergeGroups(grid, set, roots, kappa_rad, noise);
  if (landings != nullptr) *landings = std::move(merged_landings);
}

}  // namespace mlmap
