// Internal to point labelling: which of the patches near a point it was measured on,
// where two surfaces meet at an edge (a cabinet on the floor, a desk's top and front).
// Within the planes' tolerances of the edge a point lies on both; the distances alone
// decide by the range noise, the beam decides by geometry.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "mlmap/planes/point_labels.hpp"

namespace mlmap {

struct Candidate {
  std::uint32_t slot;
  double rank;   // the distance the choice among parallel planes goes by
  double meets;  // m along the beam from the point to where it meets the plane
};

// The distance of `p` from the plane (m, unsigned).
inline double planeDistance(const PointPlane& plane, const Point& p) { return std::abs(plane.normal.dot(p) + plane.offset); }

// A point near a corner of three patches lies on all of them.
constexpr std::size_t kMaxCandidates = 8;

// Beams this close to grazing a plane rank as if at this cosine (about 87°).
constexpr double kMinIncidenceCosine = 0.05;

// |n_z| of a level patch: within the detector's θ (15°).
constexpr double kLevelCosine = 0.966;
// |n_z| of a plumb patch (a wall, a box side, a riser): within θ of vertical.
constexpr double kPlumbSine = 0.259;

// Planes closer in direction than this are layers of one surface (or parallel ones),
// not two surfaces meeting at an edge: the detector's κ (25°).
constexpr double kEdgeCosine = 0.9063;

// How far along their beams each patch's own points lie from its plane: the range noise
// as that surface saw it (the planes' σ is across them, a fraction of it on a floor or
// a table seen at a grazing angle). `sigmas` times its robust estimate (the median
// offset), at least the plane's tolerance; infinite for a patch of fewer than 3 points.
// `beam_of(index)`: the unit beam of a point (zero where unknown).
std::vector<double> alongTolerances(std::span<const Point> points, std::span<const std::uint32_t> slot_of_point,
                                    const std::vector<PointPlane>& fitted,
                                    const std::function<Eigen::Vector3d(std::size_t)>& beam_of, double sigmas);

struct HeightRange {  // m; empty (low > high) where unknown
  float low = INFINITY;
  float high = -INFINITY;
};

// How high each patch reaches, from the points that lie on it alone (`sole`: the patch
// slot of each point on one patch, else 0): the height bins in which its points spread
// at least `min_width` along it, widened by a bin and two tolerances (the band where it
// meets another surface holds none of its own points). Not the points' extremes: a
// wall's points up the line where a cabinet's side meets it can lie on the side's plane
// alone, a thin trail above the cabinet's top; and the foot of a wall behind furniture is
// seen in few places, but those are wide.
std::vector<HeightRange> patchHeights(std::span<const Point> points, std::span<const std::uint32_t> sole,
                                      const std::vector<PointPlane>& fitted, double min_width);

// How far each patch's outline reaches to either side of the refitted planes of the
// patches round it: the least and the greatest signed distance of its vertices from the
// other's plane, for every pair of patches whose outlines' boxes lie within `near`.
// One key for an ordered pair of patch slots (OutlineReach, PatchSides).
inline std::uint64_t pairKey(std::uint32_t a, std::uint32_t b) { return (static_cast<std::uint64_t>(a) << 32) | b; }

class OutlineReach {
 public:
  OutlineReach(const std::vector<const std::vector<Eigen::Vector3d>*>& outline_of_slot,
               const std::vector<PointPlane>& fitted, double near);
  // [least, greatest] distance of patch a's outline from b's plane; nullopt for a pair
  // farther apart than `near` (or without an outline).
  std::optional<std::pair<double, double>> of(std::uint32_t a, std::uint32_t b) const;
  // Every pair (a, b) `of` answers for, in no particular order.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs() const;

 private:
  std::unordered_map<std::uint64_t, std::pair<float, float>> reach_;
};

// Past a surface's plane, seen from the scanner, lies only that surface's noise: a
// point there (within `tail` times its tolerance along the beam, `along_tolerance`, or
// across the plane where that is unknown) is not on a patch that ends at that plane
// on the scanner's side (a box standing on the floor, a cabinet's side or a stair tread
// against a wall) but the surface's own, however near the patch's plane it lies. The
// surface's noise tail beyond its tolerance (3σ) put single wall and floor points on such
// patches in the simulated lab and corridor at 10 cm: each of those patches then touched
// a wall or the floor (issue 19's held-out measure). Returns the surface the point lies
// behind (nearest in its tolerances), else `chosen`. Planes at an edge only (parallel
// ones are layers), and surfaces larger than the patch; a patch whose outline reaches past
// the plane by more than `slack` + the surface's tolerance does not end there (a wall
// behind a table's top).
// Only a surface the point's scanner sees from its front (`seen_from`, seenFrom) decides:
// from behind, a crate's side says nothing of its top's edge. Without the scanner
// (nullptr: a registered cloud) the surface's `seen_from` side stands for it, known for
// level surfaces by their class (levelSeenFrom).
std::uint32_t behindEdge(std::uint32_t chosen, const Point& point, const Point* scanner,
                         std::span<const Candidate> candidates, const std::vector<PointPlane>& fitted,
                         const std::vector<double>& along_tolerance, const std::vector<std::int8_t>& seen_from,
                         const OutlineReach& reach, double slack, double tail);

// A point on one patch's plane alone (within its tolerance across it) whose beam meets
// that plane farther off than the patch's range noise reaches (`along_tolerance`, from
// `rank`: the distance along the beam, grazing beams as at kMinIncidenceCosine), while it
// meets a larger surface's plane (`tail`: within `limit` of their tolerances across them)
// nearer in that surface's range noise: the surface's noise tail, not the patch. At a
// cabinet's side against a wall, the wall's points 3σ in front of it, seen along the
// side, lie on the side's plane alone (the simulated lab, 5 cm: 6 of a cabinet's, 1-3 of
// each crate's and cabinet's faces, then touching the wall or the floor). And a point
// within its range noise of both planes along the beam (the patch's and a larger surface's
// tail): either could have returned it, and as at an edge (likeliest) the larger takes it
// (the lab with 3 cm of range noise: single floor and wall points on crates' and cabinets'
// patches). Returns the surface, else `alone`'s slot.
std::uint32_t nearerAlongBeam(const Candidate& alone, std::span<const Candidate> tail,
                              const std::vector<PointPlane>& fitted, const std::vector<double>& along_tolerance,
                              double limit);

// A point given to a patch (`chosen`) that lies in the near noise tail of a much larger
// surface, within `limit` of that surface's tolerances across its plane, goes to that
// surface when the surface has at least `ratio` times the patch's points and its plane
// meets the patch's (not parallel): likeliest's edge rule (the larger takes a point on both
// planes) carried a little past the larger surface's tolerance. At a box's or a bin's foot
// the floor's points 3-4 σ up lie on the side's plane alone, and one of them makes the side
// touch the floor in an instance score. Returns the surface, else `chosen`.
// refinePointLabels passes 4/3 of a tolerance (4 σ) and a ratio of 50. make_scene.py's rooms
// (bench/peer_scene.py, 2026-12-05): walls/floor/ceiling/table F1 0.971 / 0.938 -> 0.986 / 0.978
// at 0.05 / 0.1 m (seed 1), 0.881 / 0.879 -> 0.970 / 0.972 (seeds 2-3, not looked at); mean patch
// F1 0.873 / 0.851 -> 0.861 / 0.852 and 0.867 / 0.872 -> 0.871 / 0.873 (a face gives up the strip
// within 4 σ: at 2-3 cm of noise a tread by a wall loses its match); bench/planes_sweep.py's 60
// simulated variants 0.936 -> 0.947. With a ratio of 10 the real scans of bench/real_data.py lost
// 3-5 surfaces (PCL's room scans' walls, 13x smaller than their ceiling, gave it their top
// strips); at 50 they are the same to the row (seeds 1-3).
std::uint32_t surfaceTail(std::uint32_t chosen, const Point& point, std::span<const Candidate> near,
                          const std::vector<PointPlane>& fitted, double limit, double ratio);

// Whether the beam meets the candidate's plane within that patch's range noise
// (`along_tolerance`). By its rank, not `meets`: a grazing beam (under kMinIncidenceCosine)
// meets the plane at least |distance| / kMinIncidenceCosine off, where `meets` says 0 (the
// simulated lab at 10 cm: a floor point 0.8 cm above the floor went to a patch its beam
// grazed, the floor, 3.5 cm off along the beam, left out as beyond its 3 cm).
inline bool withinRangeNoise(const Candidate& c, const std::vector<double>& along_tolerance) {
  return c.rank <= along_tolerance[c.slot];
}

// Which side of its plane a level patch of a cloud without scanners was seen from:
// above a floor, a table or a step (their open side), below a ceiling; else 0 (unknown:
// a wall's room may lie on either side).
std::int8_t levelSeenFrom(const Plane& plane, const PointPlane& fitted);

// Which side of its plane each patch was seen from: the sign of n·s + offset for the
// scanners s of most of its points (`slot_of_point`), 0 for none.
std::vector<std::int8_t> seenFrom(std::span<const Point> points, std::span<const std::uint32_t> slot_of_point,
                                  const std::vector<PointPlane>& fitted,
                                  const std::function<Point(std::size_t)>& scanner_of);

// The candidate the point was measured on (0: none). Among layers (parallel planes) the
// smallest rank. Where two surfaces meet at an edge, a point within both planes'
// tolerances lies in the strip along their line that either could have returned: its
// distances cannot tell (both are within the noise), and the beam's geometry cannot
// either, since along it both planes lie within its range noise. Such a point goes to
// the larger patch (more points), so that a box's side, a crate or a shelf ends at the
// floor or the wall it stands against instead of taking a strip of it, and the large
// surfaces reach into their corners. In the simulated lab at 5 cm that took the patches
// touching a wall, the floor, the ceiling or a table top they are not part of from 17 to
// 13, and the F1 of those surfaces over 120 held-out simulated variants from 0.79 to 0.85
// (README); the beam's order of meeting the two planes, which decided before, gave the
// floor's strip at a crate's foot to the crate wherever the crate's plane leaned out by a
// degree or counted a cell past the crate's end.
// With a beam, a plane counts only where the beam meets it on its patch (`on_patch`):
// past a cabinet's top its side's plane is air.
// Where both planes' patches are there (`on_patch`), an inside corner decides first: a
// patch that ends at the other's plane is not where its beam meets it past that plane
// (`past_corner(a, b)`; refinePointLabels asks it at a room's inside corners only). At a
// wall's top under a ceiling the beam meets the wall's plane below the ceiling or the
// ceiling's beyond the wall, never both: the planes' positions decide, not the range noise,
// so the point is the one surface's however much larger the other is (PCL's room_scan2 at
// 0.05 m: 122 of a wall's 2,226 points, some 0.4 cm from its plane and 6 cm from the
// ceiling's, went to the ceiling by size).
// At a convex rim, where a level top seen from above meets a face that ends below it and
// reaches further down than a stair's riser (a desk's front under its top, a cabinet's side),
// and at a face's foot, where a face taller than a riser stands on a level patch (its foot on
// that patch's plane and its extent within the patch's: a cabinet's front on the floor, a
// monitor on a desk): `keeps_strip(level, face)`, the strip goes to the level patch, whichever
// is larger: a top's reach to its edge is what a robot sets things on, a floor's to a
// cabinet's foot where it can drive, and the face loses a strip of noise width. By size
// the front of a generated office's desk (seen head on, 7,500-18,000 points) took 74-290
// points of its top in every variant of bench/planes_sweep.py's offices 51-56, and a face
// holding one point of a table top or the floor is a false plane in an instance score of
// the labelled surfaces.
template <typename OnPatch, typename PastCorner, typename KeepsStrip>
std::uint32_t likeliest(std::span<const Candidate> candidates, const std::vector<PointPlane>& fitted,
                        const Eigen::Vector3d& beam, OnPatch&& on_patch, PastCorner&& past_corner,
                        KeepsStrip&& keeps_strip) {
  if (candidates.empty()) return 0;
  const Candidate* best = &candidates[0];
  for (const Candidate& c : candidates)
    if (c.rank < best->rank) best = &c;
  const bool beam_known = !beam.isZero();
  for (const Candidate& c : candidates) {
    if (&c == best || std::abs(fitted[c.slot].normal.dot(fitted[best->slot].normal)) >= kEdgeCosine) continue;
    if (beam_known) {
      const bool here = on_patch(*best), there = on_patch(c);
      if (here != there) {
        if (there) best = &c;
        continue;
      }
      if (!here) continue;
      const bool here_past = past_corner(*best, c), there_past = past_corner(c, *best);
      if (here_past != there_past) {
        if (here_past) best = &c;
        continue;
      }
    }
    const bool best_keeps = keeps_strip(*best, c), c_keeps = keeps_strip(c, *best);
    if (best_keeps != c_keeps) {
      if (c_keeps) best = &c;
      continue;
    }
    if (fitted[c.slot].points > fitted[best->slot].points) best = &c;
  }
  return best->slot;
}

}  // namespace mlmap
