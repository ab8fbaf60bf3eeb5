// OctoMap scan graphs (.graph), read and written through octomap::ScanGraph:
// each node is a scan in its sensor frame with a 6D pose.
#pragma once

#include <filesystem>
#include <vector>

#include "mlmap/scan.hpp"

namespace mlmap::io {

std::vector<Scan> readScanGraph(const std::filesystem::path& path);
void writeScanGraph(const std::filesystem::path& path, const std::vector<Scan>& scans);

}  // namespace mlmap::io
