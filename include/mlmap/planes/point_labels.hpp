// Per-point plane labels: every point gets the patch id of the block that collects
// it (section IV's rule: its height within cell_size of the block's extent), so any
// point-cloud tool can use the map's planes.
#pragma once

#include <cstdint>
#include <vector>

#include "mlmap/map/ml_map.hpp"

namespace mlmap {

// One label per scan point, in order: the collecting block's plane (0 when that block
// matches no plane), or −1 when no block collects the point.
std::vector<std::int32_t> labelPoints(const MLMap& map, const Scan& scan);

}  // namespace mlmap
