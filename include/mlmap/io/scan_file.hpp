// Any supported scan file, chosen by extension: .xyz/.txt/.pts/.dat (XYZ text),
// .ply, .pcd, .3d (3DTK, with its .pose), .graph (several scans).
#pragma once

#include <filesystem>
#include <vector>

#include "mlmap/scan.hpp"

namespace mlmap::io {

// What the extension tells of a file before it is read. Throws mlmap::Error for a
// missing file or an unknown extension, as readScans would.
struct ScanFileKind {
  bool single_scan = true;  // every format but .graph holds exactly one scan
  // 3DTK (.pose), .graph, a PCD with a VIEWPOINT line; never XYZ text or PLY (nor a PCD
  // without VIEWPOINT: PCL writes one always, so a file without it says nothing of its pose).
  bool carries_pose = false;
};
ScanFileKind scanFileKind(const std::filesystem::path& path);

// One or more scans (a .graph holds several, every other format one).
std::vector<Scan> readScans(const std::filesystem::path& path);

// Writes one scan in the format its extension names; throws for unknown extensions.
void writeScan(const std::filesystem::path& path, const Scan& scan);

}  // namespace mlmap::io
