#include "mlmap/registration/map_registration.hpp"

#include <algorithm>
#include <cmath>

#include "mlmap/map/surface_points.hpp"
#include "mlmap/registration/preprocessing.hpp"

namespace mlmap::registration {

MapRegistration registerMaps(const Map& base, const Map& other, const Pose& initial_guess,
                             const MapRegistrationConfig& config) {
  const double cell_size = base.config().cell_size;
  // Voxels of a few cells: enough points per voxel for normals, few enough for speed.
  const double voxel_size = std::max(0.1, 2.0 * cell_size);
  VoxelHashMap target(voxel_size);
  target.addPoints(blockSurfacePoints(base.blocks(), cell_size));
  target.estimateNormals(NormalConfig{std::max(0.25, 3.0 * cell_size), 6, 0.05});
  const std::vector<Point> source =
      voxelDownSample(blockSurfacePoints(other.blocks(), other.config().cell_size), voxel_size);

  IcpConfig icp;
  icp.initial_max_distance = config.initial_max_distance;
  icp.min_max_distance = std::max(0.1, 2.0 * cell_size);
  icp.min_kernel_scale = std::max(0.01, cell_size / 2.0);
  icp.min_inliers = config.min_inliers;
  // Rooms mapped apart share no frame: the start may be anywhere within the basin (and the
  // retries about it); the answer is verified against the maps' own surface noise.
  BasinConfig basin = config.basin;
  // Block surfaces sit on the cell grid: their noise is at least the quantisation of a
  // cell (uniform over it: cell / √12), whatever the scans' range noise was.
  basin.min_noise = std::max(basin.min_noise, cell_size / std::sqrt(12.0));
  basin.max_start_translation = std::max(basin.max_start_translation, config.max_start_translation);
  const VerifiedIcp verified = alignVerified(source, target, initial_guess, icp, basin);
  const IcpResult& result = verified.icp;

  MapRegistration registration;
  registration.other_to_base = result.pose;
  registration.rms_residual = result.rms_residual;
  registration.inliers = result.inliers;
  registration.samples = source.size();
  registration.degenerate = result.degenerate;
  registration.verified = verified.verified;
  registration.explained_share = verified.check.explained_share;
  registration.residual_spread = verified.check.spread;
  registration.noise = verified.noise;
  registration.attempts = verified.attempts;
  const double overlap_distance = config.overlap_distance > 0.0 ? config.overlap_distance
                                                                : std::max(0.1, 2.0 * cell_size);
  std::size_t near = 0;
  const auto count = static_cast<std::int64_t>(source.size());
#pragma omp parallel for reduction(+ : near) schedule(static)
  for (std::int64_t k = 0; k < count; ++k) {
    near += target.nearest(result.pose * source[static_cast<std::size_t>(k)], overlap_distance) ? 1 : 0;
  }
  registration.overlap = source.empty() ? 0.0 : static_cast<double>(near) / static_cast<double>(source.size());

  if (source.empty() || target.empty()) {
    registration.reason = "a map has no blocks";
  } else if (registration.overlap < config.min_overlap) {
    registration.reason = "the maps overlap too little (" + std::to_string(100.0 * registration.overlap) +
                          " % of the other map's surface lies near the base map's)";
  } else if (result.inliers < config.min_inliers) {
    registration.reason = "too few ICP inliers (" + std::to_string(result.inliers) + ")";
  } else if (!verified.verified) {
    registration.reason = verified.reason;
  } else if (result.degenerate) {
    registration.reason = "the overlap does not constrain every direction (degenerate, e.g. a featureless corridor)";
  } else if (!result.converged) {
    registration.reason = "ICP did not converge";
  }
  registration.reliable = registration.reason.empty();
  return registration;
}

}  // namespace mlmap::registration
