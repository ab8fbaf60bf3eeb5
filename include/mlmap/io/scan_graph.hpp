// OctoMap scan graphs (.graph), read and written through octomap::ScanGraph:
// each node is a scan in its sensor frame with a 6D pose.
#pragma once

#include <filesystem>
#include <vector>

#include "mlmap/scan.hpp"

namespace mlmap::io {

// Binary graphs (as ScanGraph::writeBinary) and plain-ASCII logs ("NODE x y z roll
// pitch yaw" lines, as ScanGraph::readPlainASCII). Errors name "file: byte N" or
// "file:line".
std::vector<Scan> readScanGraph(const std::filesystem::path& path);

// Binary, consecutive scans linked by edges. OctoMap stores floats (points and poses
// keep about 7 significant digits); labels and variances are not stored.
void writeScanGraph(const std::filesystem::path& path, const std::vector<Scan>& scans);

}  // namespace mlmap::io
