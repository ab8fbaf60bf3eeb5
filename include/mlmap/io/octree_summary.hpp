// What an OcTree stream (OcTree::write's .ot bytes, as a .mlmap embeds them) holds,
// counted without building the tree: `mlmap info` on a 32 MB map took 6-8 s to
// allocate the whole OcTree for a line of figures.
#pragma once

#include <cstddef>
#include <string_view>

namespace mlmap::io {

struct OctreeSummary {
  double resolution = 0.0;           // m
  std::size_t nodes = 0;
  std::size_t leaves = 0;
  std::size_t occupied_leaves = 0;   // OctoMap's default threshold, probability 0.5
  std::size_t memory_bytes = 0;      // OcTree::memoryUsage() of the tree once built
};

// Throws mlmap::Error naming the byte (within `bytes`) where the stream goes wrong:
// a header that is not an OcTree's, a node count other than the header's, nodes
// deeper than the tree, bytes missing or left over.
OctreeSummary summarizeOctree(std::string_view bytes);

}  // namespace mlmap::io
