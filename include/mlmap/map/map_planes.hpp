// eRMSM on a Map: detects the planes in its blocks, labels them and keeps the planes
// with the map, so exports and `mlmap label` need no second run.
#pragma once

#include "mlmap/map/map.hpp"
#include "mlmap/planes/ermsm.hpp"

namespace mlmap {

// detectPlanes(map.blocks(), config), then map.setPlanes: the map's planes, returned.
const PlaneDetection& detectPlanes(Map& map, const ErmsmConfig& config = {});

}  // namespace mlmap
