#include "mlmap/planes/point_labels.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "edge_choice.hpp"
#include "mlmap/planes/classify.hpp"
#include "label_fits.hpp"
#include "label_candidates.hpp"
#include "level_strips.hpp"
#include "patch_sides.hpp"
#include "mlmap/error.hpp"
#include "pca_sums.hpp"

namespace mlmap {

// surfaceTail's reach, 4 σ where the tolerance is 3 σ, and the surface's size against the
// patch's (edge_choice.hpp says what they were measured on).
constexpr double kSurfaceTailTolerances = 4.0 / 3.0;
constexpr double kSurfaceTailRatio = 50.0;
// The share of a patch's points on its plane at either end of each axis left out of where
// the patch lies (LevelStrips).
constexpr double kStrayShare = 0.02;

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

// The third fit (refinePointLabels) replaces the second where at least this share of
// the points that fit used lie away from the patch's edges: a majority.
constexpr double kMinInnerShare = 0.5;

}  // namespace

std::vector<PointPlane> refinePointLabels(const MLMap& map, std::span<const Plane> planes,
                                          std::span<const Point> points, std::span<std::int32_t> labels,
                                          const PointLabelRefinement& options, const BeamOrigins& beams) {
  if (!beams.origin_of_point.empty() && beams.origin_of_point.size() != points.size())
    throw Error("refinePointLabels: " + std::to_string(beams.origin_of_point.size()) + " beam origins for " +
                std::to_string(points.size()) + " points");
  for (const std::uint32_t origin : beams.origin_of_point)
    if (origin >= beams.origins.size())
      throw Error("refinePointLabels: a point's beam origin " + std::to_string(origin) + " is out of range");
  // Patches by slot 1..n in id order; slot 0 is "none". Ids come from a map file: a
  // patch id no plane has, or a plane id ≤ 0 or repeated, is none.
  std::vector<std::int32_t> ids;
  for (const Plane& plane : planes)
    if (plane.id > 0) ids.push_back(plane.id);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  const auto slotOf = [&ids](std::int32_t id) { return slotOfId(ids, id); };
  const std::size_t slots = ids.size() + 1;
  std::vector<PointPlane> fitted(slots);
  std::vector<const Plane*> plane_of_slot(slots, nullptr);  // the first plane of each id
  std::vector<Eigen::Vector3d> origin(slots, Eigen::Vector3d::Zero());
  for (const Plane& plane : planes) {
    const std::uint32_t slot = plane.id > 0 ? slotOf(plane.id) : 0;
    if (slot == 0 || plane_of_slot[slot] != nullptr) continue;
    plane_of_slot[slot] = &plane;
    origin[slot] = plane.centroid.allFinite() ? plane.centroid : Eigen::Vector3d::Zero();
    fitted[slot].id = plane.id;
    // The normal and the offset scaled together: a normal found in float is unit to 1e-7,
    // and scaled alone it moves the plane by that share of its distance from the origin (a
    // cloud in a national grid's coordinates, 5,000 km out: 0.1-0.5 m, and a wall lost its
    // points).
    const double length = plane.normal.allFinite() ? plane.normal.norm() : 0.0;
    const bool usable = length > 0.0 && std::isfinite(plane.offset);
    fitted[slot].normal = usable ? Eigen::Vector3d(plane.normal / length) : Eigen::Vector3d::UnitZ();
    fitted[slot].offset = usable ? plane.offset / length : 0.0;
    const double rms = std::isfinite(plane.rms) ? plane.rms : 0.0;
    const double sigma = options.noise > 0.0 ? std::min(rms, options.noise) : rms;
    fitted[slot].tolerance = std::max(options.min_tolerance, options.sigmas * sigma);
  }
  std::vector<std::uint32_t> slot_of_point(points.size());
  const auto count = static_cast<std::int64_t>(points.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < count; ++k) {
    const auto index = static_cast<std::size_t>(k);
    slot_of_point[index] = labels[index] > 0 ? slotOf(labels[index]) : 0;
  }

  // Two refits, each from the points near the previous plane: the detected one, then
  // the first fit. The points of a neighbouring surface that the blocks collected
  // would tilt a fit of all of them.
  for (const double first_band : {options.band, -1.0}) {
    const std::vector<PointPlane> previous = fitted;
    const auto near_previous = [&previous, &points, first_band](std::uint32_t slot, std::size_t index) {
      const PointPlane& plane = previous[slot];
      const double band = first_band < 0.0 ? plane.tolerance : first_band;
      return band == 0.0 || planeDistance(plane, points[index]) <= band;
    };
    const std::vector<PcaSums> moments = labelledMoments(points, slot_of_point, origin, near_previous);
    for (std::size_t slot = 1; slot < slots; ++slot) fitLabelledPlane(moments[slot], origin[slot], options, fitted[slot]);
  }

  const double reach = map.cellSize();
  const auto beamOf = [&](std::size_t index) -> Eigen::Vector3d {
    if (beams.origin_of_point.empty()) return Eigen::Vector3d::Zero();
    const Eigen::Vector3d ray = points[index] - beams.origins[beams.origin_of_point[index]];
    const double length = ray.norm();
    return length > 0.0 ? Eigen::Vector3d(ray / length) : Eigen::Vector3d::Zero();
  };
  std::vector<double> along_tolerance =
      beams.origin_of_point.empty() ? std::vector<double>(slots, std::numeric_limits<double>::infinity())
                                    : alongTolerances(points, slot_of_point, fitted, beamOf, options.sigmas);
  // The patches each point may lie on (gather), read from `fitted` and `along_tolerance`
  // as the fits below move them.
  LabelCandidates candidates_of(map, points, slot_of_point, ids, fitted, along_tolerance, options.level_gap);
  // A third fit without the points at an edge: those within tolerance of the plane of a
  // patch round them that meets theirs (not parallel). The blocks along an edge collect
  // both surfaces' points, and the two fits above keep those within a band (then the
  // tolerance) of the plane, so a face leaned towards the floor at its foot and a top
  // towards its front: the simulated corridor's bench front 0.85 deg, a generated bench's
  // top 1.2 deg and 4 mm off at the edge. A leaning plane puts the other surface's points near the edge within its
  // tolerance: single points of a wall, the floor or a table top on a face's patch (issue
  // 19's held-out measure; tests/test_point_labels.cpp). The plane moves, its tolerance
  // and its count of points (edge ties go by it) stay the second fit's: the residuals
  // without the edges are the narrower, and 3 of them are too narrow for real scans'
  // heavier tails (PCL's, 3DTK's and OctoMap's walls lost 1-2 % of their points).
  // With beams, the same pass finds the one patch each point lies on, where it lies on one
  // (`sole`, for patchHeights below): the planes move by millimetres in the third fit.
  // Where the level patches' blocks lie, for the search past two cells at a face's foot:
  // built before the third fit, which first asks, on the second's planes.
  candidates_of.coverLevelPatches();
  const bool heights_wanted = !beams.origin_of_point.empty();
  std::vector<std::uint32_t> sole(heights_wanted ? points.size() : 0, 0);
  {
    std::vector<std::uint8_t> at_edge(points.size(), 0);
#pragma omp parallel for schedule(static)
    for (std::int64_t k = 0; k < count; ++k) {
      const auto index = static_cast<std::size_t>(k);
      const std::uint32_t own = slot_of_point[index];
      if (own == 0 && !heights_wanted) continue;
      std::array<Candidate, kMaxCandidates> candidates;
      const std::size_t found = candidates_of.gather(index, Eigen::Vector3d::Zero(), candidates);
      if (heights_wanted && found == 1) sole[index] = candidates[0].slot;
      if (own == 0) continue;
      for (std::size_t c = 0; c < found; ++c)
        if (candidates[c].slot != own &&
            std::abs(fitted[candidates[c].slot].normal.dot(fitted[own].normal)) < kEdgeCosine)
          at_edge[index] = 1;
    }
    // The second fit's planes: `fitted` changes only once the moments are summed.
    const auto inner = [&](std::uint32_t slot, std::size_t index) {
      return at_edge[index] == 0 && planeDistance(fitted[slot], points[index]) <= fitted[slot].tolerance;
    };
    const std::vector<PcaSums> moments = labelledMoments(points, slot_of_point, origin, inner);
    for (std::size_t slot = 1; slot < slots; ++slot) {
      PointPlane refit = fitted[slot];
      fitLabelledPlane(moments[slot], origin[slot], options, refit);
      // Mostly edge (a 17 cm riser between treads at 3 cm of range noise: half of it
      // within their tolerance): the band left is too thin to hold the plane's tilt, and
      // the corridor's risers at 3 cm noise came apart on such fits. Keep the second fit,
      // unless the inner points hold the tilt well enough that the turn is beyond their
      // error (innerFitHolds): a riser whose patch took the treads' front strips on both
      // sides is mostly edge by count, and its second fit leans 10-17° towards them.
      const bool mostly_edge = moments[slot].weight < kMinInnerShare * static_cast<double>(fitted[slot].points);
      if (mostly_edge && !innerFitHolds(moments[slot], fitted[slot].normal, refit.normal)) continue;
      fitted[slot].normal = refit.normal;  // the plane alone: tolerance and count stay
      fitted[slot].offset = refit.offset;
    }
    if (!beams.origin_of_point.empty())
      along_tolerance = alongTolerances(points, slot_of_point, fitted, beamOf, options.sigmas);
  }
  // How far each patch's outline reaches past the planes round it (behindEdge).
  std::vector<const std::vector<Eigen::Vector3d>*> outline_of_slot(slots, nullptr);
  for (std::size_t slot = 1; slot < slots; ++slot)
    if (plane_of_slot[slot] != nullptr) outline_of_slot[slot] = &plane_of_slot[slot]->outline;
  const OutlineReach outline_reach(outline_of_slot, fitted, 2.0 * reach);
  std::vector<std::int8_t> seen_from(slots, 0);
  if (!beams.origin_of_point.empty()) {
    seen_from = seenFrom(points, slot_of_point, fitted,
                         [&](std::size_t index) { return beams.origins[beams.origin_of_point[index]]; });
  } else {
    for (std::size_t slot = 1; slot < slots; ++slot)
      if (plane_of_slot[slot] != nullptr) seen_from[slot] = levelSeenFrom(*plane_of_slot[slot], fitted[slot]);
  }
  // How high each patch reaches, from the points on it alone (patchHeights).
  std::vector<HeightRange> heights(slots);
  if (heights_wanted) heights = patchHeights(points, sole, fitted, 2.0 * reach);
  // Whether the beam meets a candidate's plane where its patch is: within the height its
  // own points reach and near one of its blocks (within the plane's tolerance of the
  // block's extent, in the cells round that place). A level patch's as far as levelReach:
  // along a far wall's foot a sparse floor's blocks lie two cells off, and with one cell its
  // points stayed the wall's (planes_sweep.py: tuning scenes 3 of 240 variants better, held
  // out 3 of 60, none worse).
  const auto onPatch = [&](const Point& p, const Eigen::Vector3d& beam, const Candidate& c) {
    const Point q = p + c.meets * beam;
    const PointPlane& plane = fitted[c.slot];
    if (!(q.z() >= heights[c.slot].low && q.z() <= heights[c.slot].high)) return false;
    const auto at = map.findCellOf(q.x(), q.y());
    if (!at || !q.allFinite()) return false;
    const std::int32_t near = std::abs(plane.normal.z()) >= kLevelCosine ? candidates_of.levelReach(*at, q.z()) : kNear;
    for (std::int32_t di = -near; di <= near; ++di)
      for (std::int32_t dj = -near; dj <= near; ++dj)
        for (const Block& block : map.blocks(CellIndex{at->i + di, at->j + dj}))
          if (block.plane == plane.id && q.z() <= block.height + plane.tolerance &&
              q.z() >= block.bottom() - plane.tolerance)
            return true;
    return false;
  };
  // Whether the beam meets a's plane past b's, at a room's inside corner (likeliest): each
  // patch ends at the other's plane on the scanner's side of it (PatchSides, from the
  // outline and from the points on it alone or else of its blocks), as a wall and the
  // ceiling do, and the beam meets a's plane beyond b's by more than b's σ. At a convex edge
  // (a table top and the face below its rim, a tread's nosing) the faces are small and their
  // planes leaned a few degrees by the edge blocks they share: the plane of a simulated
  // table's rim, or a stair tread's tilted 3° by its riser, put the other's points past it
  // (bench/planes_sweep.py: the lab's tops and the corridor's treads each touched a false
  // patch, F1 0.9475 -> 0.9339), so the larger patch keeps the edge there as before.
  std::vector<std::uint32_t> side_slot(heights_wanted ? points.size() : 0);
  for (std::size_t k = 0; k < side_slot.size(); ++k) side_slot[k] = sole[k] != 0 ? sole[k] : slot_of_point[k];
  const PatchSides sides(points, side_slot, fitted, outline_reach, kEdgeCosine, reach, options.sigmas);
  const auto pastCorner = [&](std::size_t index, const Eigen::Vector3d& beam, const Candidate& a,
                              const Candidate& b) {
    const Point q = points[index] + a.meets * beam;
    const PointPlane& own = fitted[a.slot];
    const PointPlane& edge = fitted[b.slot];
    const int a_side = sides.endsAt(a.slot, b.slot, q), b_side = sides.endsAt(b.slot, a.slot, q);
    if (a_side == 0 || b_side == 0) return false;
    // Inside: the side of b's plane that a lies on (-a_side) is the scanner's, and the
    // side of a's plane that b lies on.
    const Point& scanner = beams.origins[beams.origin_of_point[index]];
    if (a_side * (edge.normal.dot(scanner) + edge.offset) >= 0.0 ||
        b_side * (own.normal.dot(scanner) + own.offset) >= 0.0)
      return false;
    return a_side * (edge.normal.dot(q) + edge.offset) > edge.tolerance / options.sigmas;
  };
  // Which of a level patch and a face keeps the strip where they meet (level_strips.hpp).
  const LevelStrips strips(fitted, seen_from, patchExtents(points, slot_of_point, fitted, kStrayShare),
                           outlineHeights(plane_of_slot), reach, ClassifyConfig{}.riser_max, kTailTolerances);
  // A point left on no patch goes back to its block's where it lies within that patch's
  // own noise (ownNoise: σ of its points within `band` of its plane), beyond the map's
  // that capped the tolerance: a wall seen far off by a depth camera lies in layers
  // several cm apart (PCL's office1 at 5 m: σ 6.8 cm against the scan's 1.4 cm), a
  // laser's far or dark wall in a wider tail. Only points of its own blocks that no other
  // patch lies near (within its tolerance or its tail): the edges keep the sensor's
  // tolerances, and a floor point at a box side's foot stays off the side.
  const std::vector<double> own_noise =
      options.noise > 0.0 ? ownNoise(points, slot_of_point, fitted, options.band) : std::vector<double>(slots, 0.0);
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < count; ++k) {
    const auto index = static_cast<std::size_t>(k);
    // Near an edge a point lies within tolerance of two planes: the more likely one
    // wins (likeliest), the collecting block's patch first among equals. The rank: with
    // its beam known, how far along the beam the plane lies from the measured point
    // (range noise lies along the beam): the distance over the cosine of the beam's
    // incidence. Else the distance in units of the plane's own spread (a floor seen at a
    // grazing angle is far thinner than a wall seen head on), which holds for the plane's
    // typical beam but not for a point seen head on where the plane is mostly seen grazing.
    const Eigen::Vector3d beam = beamOf(index);
    std::array<Candidate, kMaxCandidates> candidates, tail;
    std::size_t tail_found = 0;
    std::size_t found = candidates_of.gather(index, beam, candidates, &tail, &tail_found);
    // A surface returns a beam from its front only: with the scanner known, the patches seen
    // from the other side of their planes (seenFrom: their points' scanners) give way where
    // one faces it. A cabinet seen from two corners: its top's points by the far edges went
    // to the far sides' larger patches (tests/test_point_labels_corner.cpp: 28 % kept).
    if (found > 0 && !beams.origin_of_point.empty()) {
      const Point& scanner = beams.origins[beams.origin_of_point[index]];
      const auto facing = [&](const Candidate& c) {
        const double side = fitted[c.slot].normal.dot(scanner) + fitted[c.slot].offset;
        return seen_from[c.slot] == 0 || side * seen_from[c.slot] > 0.0;
      };
      // In place, in order (the collecting block's patch stays first), no allocation.
      const auto keepFacing = [&](std::array<Candidate, kMaxCandidates>& list, std::size_t count) {
        std::size_t kept = 0;
        for (std::size_t c = 0; c < count; ++c)
          if (facing(list[c])) list[kept++] = list[c];
        return kept;
      };
      if (std::any_of(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(found), facing)) {
        found = keepFacing(candidates, found);
        tail_found = keepFacing(tail, tail_found);
      }
    }
    // Every patch near the point, before the beam's range narrows them (behindEdge).
    std::array<Candidate, 2 * kMaxCandidates> near;
    std::copy_n(candidates.begin(), found, near.begin());
    std::copy_n(tail.begin(), tail_found, near.begin() + static_cast<std::ptrdiff_t>(found));
    const std::size_t near_found = found + tail_found;
    // Where several planes are near, one the beam meets further from the point than its
    // range noise reaches is not the one it measured (a pillar's facet, met at a grazing
    // angle in front of the floor). Alone it keeps the point: real range noise has longer
    // tails than the estimate (3-9 % of the floors of PCL's room scans lie beyond it).
    const auto within = [&](const Candidate& c) { return withinRangeNoise(c, along_tolerance); };
    if (found > 1 && std::any_of(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(found), within))
      found = static_cast<std::size_t>(std::partition(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(found), within) -
                                       candidates.begin());
    std::uint32_t chosen = likeliest(
        std::span(candidates.data(), found), fitted, beam,
        [&](const Candidate& c) { return onPatch(points[index], beam, c); },
        [&](const Candidate& a, const Candidate& b) { return pastCorner(index, beam, a, b); },
        [&](const Candidate& level, const Candidate& face) {
          return strips.of(level.slot, face.slot, points[index]) != Strip::kNone;
        });
    const std::uint32_t likeliest_choice = chosen;
    if (!beam.isZero() && found == 1)
      chosen = nearerAlongBeam(candidates[0], std::span(tail.data(), tail_found), fitted, along_tolerance,
                               kTailTolerances);
    chosen = behindEdge(chosen, points[index],
                        beams.origin_of_point.empty() ? nullptr : &beams.origins[beams.origin_of_point[index]],
                        std::span(near.data(), near_found), fitted, along_tolerance, seen_from, outline_reach, reach,
                        kTailTolerances);
    chosen = surfaceTail(chosen, points[index], std::span(near.data(), near_found), fitted, kSurfaceTailTolerances,
                         kSurfaceTailRatio);
    // The rim's strip is the top's (likeliest) whichever rule above gave it to the face below:
    // a point within the top's tolerance of its plane (the rules for a surface's tails took
    // 2-60 points of a generated desk's top, on its plane and 1.6-2.5 cm behind the front's,
    // to the front). A face's foot only where likeliest gave the point to the level patch and a
    // tail rule then moved it: there a room's inside corner decides first, and a wall's foot
    // point that the beam meets on the wall above the floor's plane stays the wall's. And a
    // point past the face's end across the level patch's plane (pastFace) is that patch's tail.
    if (chosen != 0)
      for (std::size_t c = 0; c < near_found; ++c) {
        const std::uint32_t level = near[c].slot;
        const Strip strip = strips.of(level, chosen, points[index]);
        if (strip == Strip::kNone) continue;
        const bool on_plane = planeDistance(fitted[level], points[index]) <= fitted[level].tolerance;
        if ((on_plane && (strip == Strip::kRim || likeliest_choice == level)) || strips.pastFace(level, strip, points[index])) {
          chosen = level;
          break;
        }
      }
    const std::uint32_t own = slot_of_point[index];
    if (chosen == 0 && own != 0 && planeDistance(fitted[own], points[index]) <= options.sigmas * own_noise[own] &&
        std::all_of(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(near_found),
                    [own](const Candidate& c) { return c.slot == own; }))
      chosen = own;
    if (chosen != 0)
      chosen = strips.stripOnUnseenLevel(chosen, points[index], std::span(near.data(), near_found));
    labels[index] = chosen != 0 ? fitted[chosen].id : labels[index] < 0 ? -1 : 0;
  }
  fitted.erase(fitted.begin());  // slot 0, "none"
  return fitted;
}

}  // namespace mlmap
