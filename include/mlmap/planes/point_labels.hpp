// Per-point plane labels: every point gets the patch id of the block that collects
// it (section IV's rule: its height within cell_size of the block's extent), so any
// point-cloud tool can use the map's planes.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "mlmap/map/ml_map.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "mlmap/planes/plane.hpp"

namespace mlmap {

// One label per scan point, in order: the collecting block's plane (0 when that block
// matches no plane), or −1 when no block collects the point.
std::vector<std::int32_t> labelPoints(const MLMap& map, const Scan& scan);

struct PointLabelRefinement {
  double noise = 0.0;           // m, σ of the points' range noise (the detection's), caps a patch's RMS; 0 = none
  double sigmas = 3.0;          // a point lies on a plane within sigmas × the patch's RMS of it
  double min_tolerance = 0.01;  // m, and always within this
  double band = 0.0;            // m, the first refit takes the points this close to the detected
                                // plane (e.g. ε + half a cell); 0 = all the patch's points
  double level_gap = 0.0;       // m: at a face's foot (its blocks above the point, none below)
                                // where a point's candidates are plumb faces alone, how far round
                                // its cell level patches' blocks are looked for: as far as a
                                // floor's scan lines lie apart (the detection's
                                // ErmsmConfig::sparse_gap); 0 = two cells
};

// The σ that caps a patch's tolerance (PointLabelRefinement::noise) for labels of
// `detection`'s planes. A cloud without scanners (`from_scanners` false: isotropic noise, as
// far as anything tells) has the detection's own σ, measured on the map's points where it was
// not given; capped instead by the 3 cm a build assumes for points without a variance, a
// tread's points by its riser lay within a leaning riser's 9 cm at 1 cm of noise and went to
// it (../shared/peers/make_scene.py's rooms, bench/peer_scene.py: mean F1 0.866 / 0.852 ->
// 0.883 / 0.900 at 0.05 / 0.1 m cells; Bobkov's room and plane_seg's stairs in
// bench/real_data.py found as before). Scans from scanners keep the larger of that σ and the
// build's: their range noise lies along the beam, and across surfaces seen at grazing angles
// it reads low (the simulated lab's 1 cm as 0.40 cm; capped there, bench/planes_sweep.py's
// F1 fell 0.948 -> 0.928).
inline double labelNoiseCap(const PlaneDetection& detection, bool from_scanners) {
  return from_scanners ? std::max(detection.config.noise, detection.stats.prior_noise) : detection.config.noise;
}

struct PointPlane {  // a patch's plane refitted to its points
  std::int32_t id = 0;      // the patch's id
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;      // n·x + offset = 0
  double tolerance = 0.0;   // m, points farther are not on it
  std::size_t points = 0;   // points that fitted it
};

// Where each point's beam started (world frame): the scanner's position per scan, and
// per point the index of its scan's. Empty: unknown.
struct BeamOrigins {
  std::span<const Point> origins;
  std::span<const std::uint32_t> origin_of_point;
};

// Block labels are cell-sized: a block at a corner or an edge holds points of two
// surfaces, and all of them take the block's patch. This pass refits every patch's
// plane to its labelled points (first those within `band` of the detected plane, then
// those within tolerance of the first fit); then every point takes the nearest of the
// patches it lies on (within tolerance of the plane) among its block's and those of
// the blocks of its own and the 8 neighbouring cells that reach its height (level
// patches' further round at a face's foot: `level_gap`), or none (0) if it lies on none.
// Nearest: along the point's beam when `beams` are given (range noise lies along the
// beam), else in units of each plane's tolerance. Where two surfaces meet at an edge a
// point on both goes to the larger patch; with beams, each counts only where its patch
// is, a plane the beam meets further off than that patch's range noise reaches is no
// candidate beside one it meets within it, and a point past a
// surface's plane from its scanner, in that surface's noise tail, is the surface's, not
// that of a patch ending at the plane on the scanner's side (a box on the floor).
// With `noise` set (it caps the tolerances), a point left on none goes back to its block's
// patch where it lies within `sigmas` × that patch's own robust σ (of its points within
// `band`) and no other patch lies near it: a surface noisier than the map (a far wall of a
// depth camera) keeps its tails.
// `labels` are labelPoints' (any value ≤ 0 is "none"); `points` are world points.
// Returns the refitted planes in id order (ids ≤ 0 and repeats left out). Deterministic
// at any thread count.
std::vector<PointPlane> refinePointLabels(const MLMap& map, std::span<const Plane> planes,
                                          std::span<const Point> points, std::span<std::int32_t> labels,
                                          const PointLabelRefinement& options = {}, const BeamOrigins& beams = {});

// The planes refitted to the points labelled with them (`labels` as refinePointLabels
// leaves them, ≤ 0 none; `points` world points, the same order): each plane's normal
// (its side kept), offset, centroid and RMS from the least-squares plane of its points,
// where at least 3 spread over a surface and that plane turns less than 25° (κ) from the
// detected one; else the plane as detected. Class, area, outline and ids unchanged. The
// map's planes are fitted to the points of their blocks; a point-labelled surface also
// holds the points of its cells the blocks left to no plane and not those of its blocks'
// other surfaces (`mlmap label --json`).
std::vector<Plane> refitToPoints(std::span<const Plane> planes, std::span<const Point> points,
                                 std::span<const std::int32_t> labels);

}  // namespace mlmap
