// Any supported scan file, chosen by extension: .xyz/.txt/.pts/.dat (XYZ text),
// .ply, .pcd, .3d (3DTK, with its .pose), .graph (several scans).
#pragma once

#include <filesystem>
#include <vector>

#include "mlmap/scan.hpp"

namespace mlmap::io {

// One or more scans (a .graph holds several, every other format one).
std::vector<Scan> readScans(const std::filesystem::path& path);

// Writes one scan in the format its extension names; throws for unknown extensions.
void writeScan(const std::filesystem::path& path, const Scan& scan);

}  // namespace mlmap::io
