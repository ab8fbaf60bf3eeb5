// OctoMap scan graphs through octomap::ScanGraph.
//
// Binary layout (ScanGraph::writeBinary, little-endian, what octomap's own tools
// and Debian's spherical_scan.graph use):
//   u32 node_count | node_count × node | u32 edge_count | edge_count × edge
//   node  = u32 point_count | point_count × vector | pose | u32 id
//   vector = i32 3 | 3 × f64        (28 bytes; octomap keeps floats in memory)
//   pose   = vector | i32 4 | 4 × f64 quaternion (w x y z)   (28 + 36 = 64 bytes)
//   edge  = u32 first_id | u32 second_id | pose | f64 weight   (80 bytes)
// octomap reserves memory for the counts it reads and reports errors only on
// stderr, so the layout is walked here first: every claimed count is checked
// against the bytes that remain before octomap sees the file, and the result is
// checked again (stream state, node and point counts) afterwards.
//
// The plain-ASCII log that ScanGraph::readPlainASCII reads ("NODE x y z roll pitch
// yaw" followed by "x y z" lines) is recognised by its first byte and parsed here
// with the strict TextLines reader instead, because octomap's reader silently
// skips lines it cannot parse; poses still go through octomath::Pose6D so the
// Euler convention is octomap's.
//
// Only points and poses are stored: labels and variances do not survive a .graph.
#include "mlmap/io/scan_graph.hpp"

#include <octomap/ScanGraph.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "captured_cerr.hpp"
#include "file_bytes.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/atomic_file.hpp"
#include "text_lines.hpp"

namespace mlmap::io {
namespace {

constexpr std::uint64_t kCountBytes = 4;
constexpr std::uint64_t kVectorBytes = 4 + 3 * 8;
constexpr std::uint64_t kPoseBytes = kVectorBytes + 4 + 4 * 8;
constexpr std::uint64_t kNodeIdBytes = 4;
constexpr std::uint64_t kMinNodeBytes = kCountBytes + kPoseBytes + kNodeIdBytes;
constexpr std::uint64_t kEdgeBytes = 4 + 4 + kPoseBytes + 8;
constexpr double kMinQuaternionNorm = 1e-6;

[[noreturn]] void failAtByte(const std::filesystem::path& path, std::uint64_t byte,
                             const std::string& what) {
  throw Error(path.string() + ": byte " + std::to_string(byte) + ": " + what);
}

// Where each node's data starts, as found by walking the binary layout.
struct NodeLayout {
  std::uint64_t offset = 0;  // of the node's point count
  std::uint32_t point_count = 0;
};

std::uint32_t readCount(std::ifstream& in, const std::filesystem::path& path,
                        std::uint64_t offset) {
  unsigned char bytes[4];
  in.seekg(static_cast<std::streamoff>(offset));
  in.read(reinterpret_cast<char*>(bytes), 4);
  if (!in) failAtByte(path, offset, "cannot read a count");
  return static_cast<std::uint32_t>(bytes[0]) | static_cast<std::uint32_t>(bytes[1]) << 8 |
         static_cast<std::uint32_t>(bytes[2]) << 16 | static_cast<std::uint32_t>(bytes[3]) << 24;
}

// Checks that the counts in the file are consistent with its size before any
// memory is allocated for them.
std::vector<NodeLayout> walkBinaryLayout(const std::filesystem::path& path,
                                         std::uint64_t file_size) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open for reading");
  if (file_size < 2 * kCountBytes) {
    failAtByte(path, 0,
               "file too short for a scan graph (" + std::to_string(file_size) + " bytes)");
  }
  const std::uint32_t node_count = readCount(in, path, 0);
  std::uint64_t offset = kCountBytes;
  if (node_count == 0) failAtByte(path, 0, "scan graph holds no scans");
  if (static_cast<std::uint64_t>(node_count) * kMinNodeBytes > file_size - offset) {
    failAtByte(path, 0,
               "header claims " + std::to_string(node_count) + " scans but only " +
                   std::to_string(file_size - offset) + " bytes follow");
  }
  std::vector<NodeLayout> nodes;
  nodes.reserve(node_count);
  for (std::uint32_t node = 0; node < node_count; ++node) {
    if (file_size - offset < kMinNodeBytes) {
      failAtByte(path, offset, "file ends inside scan " + std::to_string(node));
    }
    const std::uint32_t point_count = readCount(in, path, offset);
    const std::uint64_t node_bytes = kCountBytes +
                                     static_cast<std::uint64_t>(point_count) * kVectorBytes +
                                     kPoseBytes + kNodeIdBytes;
    if (node_bytes > file_size - offset) {
      failAtByte(path, offset,
                 "scan " + std::to_string(node) + " claims " + std::to_string(point_count) +
                     " points but only " + std::to_string(file_size - offset) + " bytes remain");
    }
    nodes.push_back({offset, point_count});
    offset += node_bytes;
  }
  if (file_size - offset < kCountBytes) failAtByte(path, offset, "file ends before the edge count");
  const std::uint32_t edge_count = readCount(in, path, offset);
  const std::uint64_t edge_bytes = static_cast<std::uint64_t>(edge_count) * kEdgeBytes;
  if (edge_bytes != file_size - offset - kCountBytes) {
    failAtByte(path, offset,
               "edge count " + std::to_string(edge_count) + " needs " + std::to_string(edge_bytes) +
                   " bytes but " + std::to_string(file_size - offset - kCountBytes) + " follow");
  }
  return nodes;
}

// octomath's pose to Eigen; the quaternion is normalised (stored as float) and
// must not be zero.
std::optional<Pose> toPose(const octomath::Pose6D& pose) {
  Eigen::Quaterniond rotation(pose.rot().u(), pose.rot().x(), pose.rot().y(), pose.rot().z());
  const double norm = rotation.norm();
  const Eigen::Vector3d translation(pose.trans().x(), pose.trans().y(), pose.trans().z());
  if (!(norm >= kMinQuaternionNorm) || !std::isfinite(norm) || !translation.allFinite()) {
    return std::nullopt;
  }
  rotation.coeffs() /= norm;
  Pose result = Pose::Identity();
  result.linear() = rotation.toRotationMatrix();
  result.translation() = translation;
  return result;
}

std::vector<Scan> readBinaryGraph(const std::filesystem::path& path, std::uint64_t file_size) {
  const std::vector<NodeLayout> layout = walkBinaryLayout(path, file_size);

  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open for reading");
  octomap::ScanGraph graph;
  {
    const CapturedCerr quiet;  // ScanGraph reports progress on std::cerr
    graph.readBinary(in);
  }
  if (in.fail() || graph.size() != layout.size()) {
    throw Error(path.string() + ": octomap could not read the scan graph (read " +
                std::to_string(graph.size()) + " of " + std::to_string(layout.size()) + " scans)");
  }

  std::vector<Scan> scans;
  scans.reserve(layout.size());
  std::size_t index = 0;
  for (const octomap::ScanNode* node : graph) {
    const NodeLayout& where = layout[index];
    if (node->scan == nullptr || node->scan->size() != where.point_count) {
      failAtByte(path, where.offset,
                 "scan " + std::to_string(index) + ": octomap read a different point count");
    }
    Scan scan;
    const std::uint64_t pose_offset = where.offset + kCountBytes + where.point_count * kVectorBytes;
    const auto pose = toPose(node->pose);
    if (!pose) {
      failAtByte(path, pose_offset,
                 "scan " + std::to_string(index) + ": pose is not finite or its quaternion is zero");
    }
    scan.pose = *pose;
    scan.points.reserve(node->scan->size());
    for (std::size_t i = 0; i < node->scan->size(); ++i) {
      const octomap::point3d& p = (*node->scan)[i];
      const Point point(p.x(), p.y(), p.z());
      if (!point.allFinite()) {
        failAtByte(
            path, where.offset + kCountBytes + i * kVectorBytes,
            "scan " + std::to_string(index) + ": point " + std::to_string(i) + " is not finite");
      }
      scan.points.push_back(point);
    }
    scans.push_back(std::move(scan));
    ++index;
  }
  return scans;
}

std::vector<Scan> readAsciiGraph(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open for reading");
  TextLines lines(in, path.string());
  std::vector<Scan> scans;
  while (lines.next()) {
    const auto fields = lines.fields(/*hash_comments=*/true);
    if (fields.empty()) continue;
    if (fields[0] == "NODE") {
      if (fields.size() != 7) {
        lines.fail("expected 'NODE x y z roll pitch yaw', found " + std::to_string(fields.size()) +
                   " fields");
      }
      double values[6];
      for (int i = 0; i < 6; ++i) values[i] = lines.parseDouble(fields[i + 1]);
      const octomath::Pose6D pose(static_cast<float>(values[0]), static_cast<float>(values[1]),
                                  static_cast<float>(values[2]), values[3], values[4], values[5]);
      const auto converted = toPose(pose);
      if (!converted) lines.fail("pose is not finite");
      scans.emplace_back();
      scans.back().pose = *converted;
      continue;
    }
    if (scans.empty()) lines.fail("point before the first NODE line");
    if (fields.size() < 3) {
      lines.fail("expected at least 3 fields (x y z), found " + std::to_string(fields.size()));
    }
    scans.back().points.emplace_back(lines.parseDouble(fields[0]), lines.parseDouble(fields[1]),
                                     lines.parseDouble(fields[2]));
  }
  if (scans.empty()) {
    throw Error(path.string() + ":" + std::to_string(std::max<std::size_t>(lines.lineNumber(), 1)) +
                ": no NODE line, no scans in file");
  }
  return scans;
}

// A binary graph starts with its node count; four printable bytes ("NODE", "# co")
// would claim over 150 million scans, i.e. a file of more than 10 GB of nothing but
// empty scans, so text at the start means the ASCII log.
bool looksLikeAscii(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  char start[4] = {};
  in.read(start, 4);
  if (!in) return false;
  const bool text = std::all_of(std::begin(start), std::end(start), [](char c) {
    return (c >= 0x20 && c < 0x7f) || c == '\t' || c == '\n' || c == '\r';
  });
  return text && (std::string_view(start, 4) == "NODE" || start[0] == '#');
}

}  // namespace

std::vector<Scan> readScanGraph(const std::filesystem::path& path) {
  requireRegularFile(path);
  std::error_code error;
  const std::uint64_t file_size = std::filesystem::file_size(path, error);
  if (error) throw Error(path.string() + ": cannot read size (" + error.message() + ")");
  if (looksLikeAscii(path)) return readAsciiGraph(path);
  return readBinaryGraph(path, file_size);
}

void writeScanGraph(const std::filesystem::path& path, const std::vector<Scan>& scans) {
  if (scans.empty()) throw Error(path.string() + ": no scans to write");
  octomap::ScanGraph graph;
  for (std::size_t index = 0; index < scans.size(); ++index) {
    const Scan& scan = scans[index];
    if (scan.points.size() > 0xFFFFFFFFu)
      throw Error(path.string() + ": scan " + std::to_string(index) + " too large");
    if (!scan.pose.matrix().allFinite()) {
      throw Error(path.string() + ": scan " + std::to_string(index) + ": pose is not finite");
    }
    auto cloud = std::make_unique<octomap::Pointcloud>();
    cloud->reserve(scan.points.size());
    for (std::size_t i = 0; i < scan.points.size(); ++i) {
      const Point& p = scan.points[i];
      if (!p.allFinite()) {
        throw Error(path.string() + ": scan " + std::to_string(index) + ": point " +
                    std::to_string(i) + " is not finite");
      }
      cloud->push_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                       static_cast<float>(p.z()));
    }
    const Eigen::Quaterniond rotation(scan.pose.linear());
    const Eigen::Vector3d& t = scan.pose.translation();
    const octomath::Pose6D pose(
        octomath::Vector3(static_cast<float>(t.x()), static_cast<float>(t.y()),
                          static_cast<float>(t.z())),
        octomath::Quaternion(static_cast<float>(rotation.w()), static_cast<float>(rotation.x()),
                             static_cast<float>(rotation.y()), static_cast<float>(rotation.z())));
    graph.addNode(cloud.release(), pose);  // the graph owns the cloud from here
    graph.connectPrevious();               // octomap's tools expect consecutive scans linked
  }
  writeAtomically(path, [&](std::ostream& out) {
    const CapturedCerr quiet;
    graph.writeBinary(out);
  });
}

}  // namespace mlmap::io
