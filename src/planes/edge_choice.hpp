// Internal to point labelling: which of the patches near a point it was measured on,
// where two surfaces meet at an edge (a cabinet on the floor, a desk's top and front).
// Within the planes' tolerances of the edge a point lies on both; the distances alone
// decide by the range noise, the beam decides by geometry.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "mlmap/planes/point_labels.hpp"

namespace mlmap {

struct Candidate {
  std::uint32_t slot;
  double rank;   // the distance the choice among parallel planes goes by
  double meets;  // m along the beam from the point to where it meets the plane
};

// A point near a corner of three patches lies on all of them.
constexpr std::size_t kMaxCandidates = 8;

// Beams this close to grazing a plane rank as if at this cosine (about 87°).
constexpr double kMinIncidenceCosine = 0.05;

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
template <typename OnPatch>
std::uint32_t likeliest(std::span<const Candidate> candidates, const std::vector<PointPlane>& fitted,
                        const Eigen::Vector3d& beam, OnPatch&& on_patch) {
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
    }
    if (fitted[c.slot].points > fitted[best->slot].points) best = &c;
  }
  return best->slot;
}

}  // namespace mlmap
