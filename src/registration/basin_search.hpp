// Internal to alignVerified: the ICP runs from one start and the choice among them (see
// verified_icp.hpp for the whole). One run as asked; where it does not verify, the wide
// basin from the start and from offsets about it; the kept result refined at the asked
// gates, fitted along a weak direction by the points facing it, and weighed against its
// turned rivals; then the verdict and the reason said to the user.
#pragma once

#include <vector>

#include "mlmap/registration/icp.hpp"
#include "mlmap/registration/verified_icp.hpp"
#include "mlmap/registration/voxel_hash_map.hpp"
#include "mlmap/scan.hpp"

namespace mlmap::registration {

// The RMS range of a cloud's points from its origin (its sensor), m, at least 1: turns are
// scaled to metres at it.
double cloudRadius(const std::vector<Point>& source);

// alignVerified's search, its arguments checked: `source` and `target` not empty and
// `surfaces` the source's.
VerifiedIcp searchBasin(const std::vector<Point>& source, const CloudSurfaces& surfaces, const VoxelHashMap& target,
                        const Pose& start, const IcpConfig& icp, const BasinConfig& config);

}  // namespace mlmap::registration
