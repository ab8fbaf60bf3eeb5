// The blocks of a map as a PLY point cloud (binary little-endian), one vertex per
// block at its point (cell centre, at h for horizontal blocks, mid-height for
// vertical ones) with the normal of its plane, its label and the palette's colour,
// for CloudCompare, MeshLab or Open3D.
#pragma once

#include <filesystem>

#include "mlmap/map/map.hpp"

namespace mlmap::io {

// Vertex properties: float x y z, float nx ny nz (the plane's normal; 0 0 0 for
// blocks without a plane), int label (0 = none), uchar red green blue, float depth,
// uchar vertical. Written atomically.
void writeBlocksPly(const std::filesystem::path& path, const Map& map);

}  // namespace mlmap::io
