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
// scatter along the normal, in squares). nullopt below `min_blocks` such blocks: the
// median of 100 blocks drawn at random from the labelled blocks of the eight real scans
// of bench/real_data.py (5 and 10 cm cells) lies within -11..-29 % and +15..+41 % of the
// median of all (95 % of 400 draws), about the 25 % that decides a second pass; of 30
// blocks within -17..-43 % and +30..+88 %, which would decide it by chance.
std::optional<double> surfaceNoise(const MLMap& map, const std::vector<Plane>& planes, std::size_t min_blocks = 100);

}  // namespace mlmap
