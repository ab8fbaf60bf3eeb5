// The slide profile of an alignment: does anything in the scans fix the pose along its
// weakest direction, and where? The weakest direction d is the translation the matched
// points' point-to-plane normal equations constrain least (along a corridor: its axis). Only
// the source points whose own surface faces d (an end wall, a niche's side, a locker's front
// for a corridor) can measure a slide along it; the profile counts how many of them land on a
// target surface that also faces d (point-to-plane residual within the explained bound) as
// the pose slides along d. A true alignment stands out as a peak there; a slid one lies where
// the profile is flat or peaks elsewhere.
//
// Why not the eigenvalues alone: along a corridor the walls' leaning normals (range noise,
// neighbourhoods at grazing incidence) add spurious information along the axis, so a result
// slid 0.5-1 m along it can have a larger eigenvalue ratio than a true one in a corridor
// whose only fixing surfaces are a few niches (measured on the stress benchmark: slid results
// 1.2e-2 to 1.5e-2, true long-corridor results 3e-3 to 6e-3).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "mlmap/registration/voxel_hash_map.hpp"
#include "mlmap/scan.hpp"

namespace mlmap::registration {

struct SlideProfile {
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit, target frame
  std::size_t facing = 0;     // source points (of those sampled) whose surface faces ±d
  std::size_t at_result = 0;  // of them explained at the pose itself
  std::size_t away = 0;       // the most explained at any shift beyond the peak's half width
  std::size_t best = 0;       // the most explained at any shift
  double best_shift = 0.0;    // m, along d, where `best` was counted
  double half_width = 0.0;    // m, how far a shift still explains a point explained at 0
  bool peaked = false;        // at_result stands out from `away` (3 standard errors of the counts)
  bool better_elsewhere = false;  // `best` stands out from at_result in the same way
};

// The profile of `pose` (source -> target) along the weakest direction of
// `translation_information` (the 3×3 translation block of the matched points' point-to-plane
// normal equations), over shifts in [lowest, highest] (m) at `step`; a point is explained
// when its point-to-plane residual is within `bound` (m). `source_normals` holds one unit
// normal per source point (zero: none; such points never count).
SlideProfile slideProfile(const std::vector<Point>& source, const std::vector<Eigen::Vector3d>& source_normals,
                          const VoxelHashMap& target, const Pose& pose,
                          const Eigen::Matrix3d& translation_information, double bound, double lowest,
                          double highest, double step);

// Where along `direction` (unit, target frame) the source points whose own surface faces it
// sit best on target surfaces facing it: the shift s (m) minimising the squared point-to-plane
// residuals of those within `bound` of their match, re-matched at each step from `pose`. Only
// such points measure a slide along a corridor (the walls' leaning normals would pull too); the
// slide profile counts them at steps of 2σ, this fits them. No shift when fewer than
// `min_points` match.
struct SlideFit {
  double shift = 0.0;           // m, along the direction
  double standard_error = 0.0;  // m, of the shift (residual spread over √Σ(n·d)²)
  std::size_t points = 0;       // matched facing points at the last step
  bool fitted = false;
};
SlideFit fitSlide(const std::vector<Point>& source, const std::vector<Eigen::Vector3d>& source_normals,
                  const VoxelHashMap& target, const Pose& pose, const Eigen::Vector3d& direction, double bound,
                  std::size_t min_points);

// One normal per point of `points` (their own neighbourhood's PCA normal, zero where it is
// not planar), and the cloud's surface noise (VoxelHashMap::surfaceNoise), from one voxel
// hash of the points at `voxel_size` with normals over twice that radius, grown up to 8 voxels
// where that is too sparse (a far end wall: NormalConfig::max_radius).
struct CloudSurfaces {
  std::vector<Eigen::Vector3d> normals;
  double noise = 0.0;  // m
};
CloudSurfaces cloudSurfaces(const std::vector<Point>& points, double voxel_size);

}  // namespace mlmap::registration
