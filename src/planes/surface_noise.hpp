// Internal to eRMSM: the range noise measured on the map's own points, about the planes a
// first detection found (issue 19: "noise measured from the data").
#pragma once

#include <optional>
#include <vector>

#include "mlmap/map/ml_map.hpp"
#include "mlmap/planes/plane.hpp"

namespace mlmap {

// The median, over the labelled blocks that keep their points' moments, of the RMS
// distance of a block's points from its patch's plane (the mean's distance and the
// scatter along the normal, in squares). nullopt below `min_blocks` such blocks.
std::optional<double> surfaceNoise(const MLMap& map, const std::vector<Plane>& planes, std::size_t min_blocks = 100);

}  // namespace mlmap
