// Chooses a reader or writer by the file's extension, compared case-insensitively.
#include "mlmap/io/scan_file.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <string>

#include "mlmap/error.hpp"
#include "mlmap/io/pcd.hpp"
#include "mlmap/io/ply.hpp"
#include "mlmap/io/regular_file.hpp"
#include "mlmap/io/scan_graph.hpp"
#include "mlmap/io/threedtk.hpp"
#include "mlmap/io/xyz.hpp"

namespace mlmap::io {
namespace {

enum class Format { Xyz, Ply, Pcd, ThreeDtk, Graph };

constexpr const char* kSupported = ".xyz .txt .pts .dat (XYZ text), .ply, .pcd, .3d (3DTK), .graph";

Format formatOf(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".xyz" || extension == ".txt" || extension == ".pts" || extension == ".dat") {
    return Format::Xyz;
  }
  if (extension == ".ply") return Format::Ply;
  if (extension == ".pcd") return Format::Pcd;
  if (extension == ".3d") return Format::ThreeDtk;
  if (extension == ".graph") return Format::Graph;
  throw Error(path.string() + ": unknown scan format '" + path.extension().string() +
              "' (supported: " + kSupported + ")");
}

std::vector<Scan> single(Scan scan) {
  std::vector<Scan> scans;
  scans.push_back(std::move(scan));  // a braced list would copy every point
  return scans;
}

// A device or a pipe never ends: a .pcd linked to /dev/zero had its header read forever.
void requireScanFile(const std::filesystem::path& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) throw Error(path.string() + ": is a directory, not a scan file");
  requireRegularFile(path);
}

// Reads the header lines only (up to DATA, at most 64 KB): readPcd parses them properly.
bool pcdHeaderHasViewpoint(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::size_t read = 0;
  while (read < (64u << 10) && std::getline(in, line)) {
    read += line.size() + 1;
    if (line.rfind("VIEWPOINT", 0) == 0) return true;
    if (line.rfind("DATA", 0) == 0) return false;
  }
  return false;
}

}  // namespace

ScanFileKind scanFileKind(const std::filesystem::path& path) {
  const Format format = formatOf(path);
  requireScanFile(path);
  return ScanFileKind{.single_scan = format != Format::Graph,
                      .carries_pose = format == Format::ThreeDtk || format == Format::Graph ||
                                      (format == Format::Pcd && pcdHeaderHasViewpoint(path))};
}

std::vector<Scan> readScans(const std::filesystem::path& path) {
  const Format format = formatOf(path);
  requireScanFile(path);
  switch (format) {
    case Format::Xyz:
      return single(readXyz(path));
    case Format::Ply:
      return single(readPly(path));
    case Format::Pcd:
      return single(readPcd(path));
    case Format::ThreeDtk:
      return single(readThreeDtkScan(path));
    case Format::Graph:
      return readScanGraph(path);
  }
  // Unreachable: formatOf() either names a handled format or throws.
  throw Error(path.string() + ": unhandled scan format");
}

void writeScan(const std::filesystem::path& path, const Scan& scan) {
  switch (formatOf(path)) {
    case Format::Xyz:
      writeXyz(path, scan);
      return;
    case Format::Ply:
      writePly(path, scan);
      return;
    case Format::Pcd:
      writePcd(path, scan);
      return;
    case Format::ThreeDtk:
      writeThreeDtkScan(path, scan);
      return;
    case Format::Graph:
      writeScanGraph(path, {scan});
      return;
  }
}

}  // namespace mlmap::io
