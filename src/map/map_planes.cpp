#include "mlmap/map/map_planes.hpp"

namespace mlmap {

const PlaneDetection& detectPlanes(Map& map, const ErmsmConfig& config) {
  map.setPlanes(detectPlanes(map.blocks(), config));
  return *map.planes();
}

}  // namespace mlmap
