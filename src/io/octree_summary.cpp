#include "mlmap/io/octree_summary.hpp"

#include <octomap/OcTree.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "mlmap/error.hpp"

namespace mlmap::io {
namespace {

[[noreturn]] void fail(std::size_t offset, const std::string& what) {
  throw Error("OcTree byte " + std::to_string(offset) + ": " + what);
}

// The header's lines up to and including "data": "# ..." comments, "id OcTree",
// "size N", "res R" (AbstractOcTree::write). Returns the offset of the first node.
std::size_t readHeader(std::string_view bytes, std::size_t& declared_nodes, OctreeSummary& summary) {
  const std::string_view first = "# Octomap OcTree file";
  if (bytes.substr(0, first.size()) != first) fail(0, "not an OcTree stream (no \"" + std::string(first) + "\")");
  bool has_id = false;
  bool has_size = false;
  std::size_t offset = 0;
  while (offset < bytes.size()) {
    const std::size_t end = bytes.find('\n', offset);
    if (end == std::string_view::npos) break;
    const std::string line(bytes.substr(offset, end - offset));
    const std::size_t line_offset = offset;
    offset = end + 1;
    if (line.empty() || line[0] == '#') continue;
    const std::size_t space = line.find(' ');
    const std::string keyword = line.substr(0, space);
    const std::string value = space == std::string::npos ? std::string() : line.substr(space + 1);
    if (keyword == "data") {
      if (!has_id || !has_size || !(summary.resolution > 0.0)) fail(line_offset, "header without id, size or res");
      return offset;
    }
    try {
      std::size_t used = 0;
      if (keyword == "id") {
        if (value != "OcTree") fail(line_offset, "tree type \"" + value + "\", not OcTree");
        has_id = true;
      } else if (keyword == "size") {
        declared_nodes = std::stoull(value, &used);
        has_size = used == value.size();
      } else if (keyword == "res") {
        summary.resolution = std::stod(value, &used);
        if (used != value.size()) summary.resolution = 0.0;
      }
    } catch (const std::logic_error&) {  // stoull / stod: not a number, out of range
      fail(line_offset, "bad header line \"" + line.substr(0, 40) + "\"");
    }
  }
  fail(bytes.size(), "the header has no \"data\" line");
}

}  // namespace

OctreeSummary summarizeOctree(std::string_view bytes) {
  OctreeSummary summary;
  std::size_t declared_nodes = 0;
  std::size_t offset = readHeader(bytes, declared_nodes, summary);
  // Nodes depth first, each its log-odds (f32) and a byte of child bits
  // (OcTreeBaseImpl::writeNodesRecurs). `open` holds, per inner node on the path,
  // the children still to come.
  constexpr std::size_t kNodeBytes = sizeof(float) + 1;
  const float occupied_from = octomap::logodds(0.5);  // AbstractOccupancyOcTree's default threshold
  std::vector<unsigned> open;
  while (declared_nodes > 0 && (summary.nodes == 0 || !open.empty())) {
    if (bytes.size() - offset < kNodeBytes) fail(offset, "the stream ends inside the nodes");
    if (open.size() > 16) fail(offset, "a node deeper than the tree's 16 levels");
    float log_odds = 0.0F;
    std::memcpy(&log_odds, bytes.data() + offset, sizeof(log_odds));
    const auto children = static_cast<unsigned char>(bytes[offset + sizeof(float)]);
    offset += kNodeBytes;
    ++summary.nodes;
    if (!open.empty()) --open.back();
    if (children != 0) {
      open.push_back(static_cast<unsigned>(std::popcount(children)));
    } else {
      ++summary.leaves;
      summary.occupied_leaves += log_odds >= occupied_from ? 1 : 0;
    }
    while (!open.empty() && open.back() == 0) open.pop_back();
  }
  if (summary.nodes != declared_nodes) {
    fail(offset, "the header says " + std::to_string(declared_nodes) + " nodes, the stream holds " +
                     std::to_string(summary.nodes));
  }
  if (offset != bytes.size()) fail(offset, std::to_string(bytes.size() - offset) + " bytes after the last node");
  using Base = octomap::OcTreeBaseImpl<octomap::OcTreeNode, octomap::AbstractOccupancyOcTree>;
  summary.memory_bytes = sizeof(Base) + sizeof(octomap::OcTreeNode) * summary.nodes +
                         (summary.nodes - summary.leaves) * sizeof(octomap::OcTreeNode* [8]);
  return summary;
}

}  // namespace mlmap::io
