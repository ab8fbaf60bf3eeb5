// 3DTK ("uos") scans: scanNNN.3d (x y z in centimetres, left-handed, y up, z forward)
// with scanNNN.pose (position in cm, then Euler angles in degrees).
// Converted to metres in mlmap's right-handed z-up frame (see the .cpp for the maths).
#pragma once

#include <filesystem>

#include "mlmap/scan.hpp"

namespace mlmap::io {

// Reads `path` (the .3d file) and its sibling .pose (required) into a Scan whose
// points are in the sensor frame and whose pose maps them to the world, in metres.
Scan readThreeDtkScan(const std::filesystem::path& path);

// The inverse, for round trips and for feeding 3DTK tools: writes `path` and its
// sibling .pose, each atomically. Labels and variances are not stored.
void writeThreeDtkScan(const std::filesystem::path& path, const Scan& scan);

}  // namespace mlmap::io
