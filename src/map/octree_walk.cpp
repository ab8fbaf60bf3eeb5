// One scan's voxel updates into the OcTree, each step the one OccupancyOcTreeBase::
// updateNode (lazy_eval = false) takes, in Morton (depth-first) order so that a key
// descends only from the deepest node it shares with the previous one and an inner node
// is brought up to date once, when the walk leaves it.
//
// Subtrees below a split depth hold disjoint keys, and a node's update reads only its
// own children: each subtree is walked by one thread, then the few nodes above the
// split are settled serially, deepest first. OctoMap's createNodeChild, expandNode and
// pruneNode count nodes in a member of the tree (tree_size++), a data race between
// threads; NodeEdits does the same allocations and deletions and counts the nodes per
// walk, added to the tree once.
#include "octree_walk.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap::detail {
namespace {

using octomap::AbstractOcTreeNode;
using octomap::OcTreeNode;

constexpr unsigned kDepth = 16;
constexpr unsigned kChunkDepth = kDepth - kChunkBits;  // the depth of a chunk's node

// OctoMap's protected members, through pointers to members taken in derived classes
// (the access C++ gives a derived class; nothing is instantiated).
struct TreeMembers : octomap::OcTree {
  static constexpr auto kRoot = &TreeMembers::root;
  static constexpr auto kSize = &TreeMembers::tree_size;
  static constexpr auto kSizeChanged = &TreeMembers::size_changed;
};
struct NodeMembers : OcTreeNode {
  static constexpr auto kChildren = &NodeMembers::children;
};

// createNodeChild, expandNode and pruneNode of OcTreeBaseImpl (OctoMap 1.9), step for
// step, without touching the tree's node count.
class NodeEdits {
 public:
  explicit NodeEdits(const octomap::OcTree& tree) : tree_(tree) {}

  OcTreeNode* createChild(OcTreeNode* node, unsigned index) {
    AbstractOcTreeNode**& children = node->*NodeMembers::kChildren;
    if (children == nullptr) {
      children = new AbstractOcTreeNode*[8];
      std::fill_n(children, 8, nullptr);
    }
    auto* child = new OcTreeNode();
    children[index] = child;
    ++nodes_added_;
    return child;
  }

  void expand(OcTreeNode* node) {
    for (unsigned k = 0; k < 8; ++k) createChild(node, k)->copyData(*node);
  }

  bool prune(OcTreeNode* node) {
    if (!tree_.isNodeCollapsible(node)) return false;
    node->copyData(*tree_.getNodeChild(node, 0));
    AbstractOcTreeNode**& children = node->*NodeMembers::kChildren;
    for (unsigned k = 0; k < 8; ++k) delete static_cast<OcTreeNode*>(children[k]);
    delete[] children;
    children = nullptr;
    nodes_added_ -= 8;
    return true;
  }

  // Brings an inner node up to date, or prunes it, as updateNodeRecurs does on its way up.
  void settle(OcTreeNode* node) {
    if (!tree_.nodeHasChildren(node)) return;
    if (!prune(node)) node->updateOccupancyChildren();
  }

  std::ptrdiff_t nodesAdded() const { return nodes_added_; }

 private:
  const octomap::OcTree& tree_;
  std::ptrdiff_t nodes_added_ = 0;
};

unsigned childOf(std::uint64_t code, unsigned depth) {
  return static_cast<unsigned>(code >> (3 * (kDepth - 1 - depth))) & 7U;
}

// Walks the keys below one node (the root, or a subtree's root at `top`) in ascending
// Morton code, keeping the path of the previous key.
class TreeWalk {
 public:
  TreeWalk(const octomap::OcTree& tree, OcTreeNode* top, unsigned top_depth, bool top_created)
      : tree_(tree), edits_(tree), top_depth_(top_depth), valid_(top_depth) {
    path_[top_depth] = top;
    created_[top_depth] = top_created;
  }

  void visit(std::uint64_t code, float update) {
    if (started_) {
      const auto group = static_cast<unsigned>(63 - std::countl_zero(code ^ previous_)) / 3;
      close(kDepth - 1 - group);
    }
    started_ = true;
    previous_ = code;
    for (unsigned d = valid_; d < kDepth; ++d) {
      OcTreeNode* node = path_[d];
      const unsigned child = childOf(code, d);
      created_[d + 1] = false;
      if (!tree_.nodeChildExists(node, child)) {
        if (!tree_.nodeHasChildren(node) && !created_[d]) {
          // A pruned node: updateNode's early abort leaves it whole when saturated.
          if (saturated(*node, update)) {
            valid_ = d;
            return;
          }
          edits_.expand(node);
        } else {
          edits_.createChild(node, child);
          created_[d + 1] = true;
        }
      }
      path_[d + 1] = tree_.getNodeChild(node, child);
    }
    valid_ = kDepth;
    if (!saturated(*path_[kDepth], update)) tree_.updateNodeLogOdds(path_[kDepth], update);
  }

  // Brings the nodes still on the path up to date, the top one last.
  void finish() {
    if (!started_) return;
    close(top_depth_);
    edits_.settle(path_[top_depth_]);
  }

  std::ptrdiff_t nodesAdded() const { return edits_.nodesAdded(); }

 private:
  bool saturated(const OcTreeNode& node, float update) const {
    return (update >= 0 && node.getLogOdds() >= tree_.getClampingThresMaxLog()) ||
           (update <= 0 && node.getLogOdds() <= tree_.getClampingThresMinLog());
  }

  // Leaves the nodes deeper than `depth`, deepest first.
  void close(unsigned depth) {
    for (; valid_ > depth; --valid_) {
      if (valid_ < kDepth) edits_.settle(path_[valid_]);
    }
  }

  const octomap::OcTree& tree_;
  NodeEdits edits_;
  unsigned top_depth_;
  std::array<OcTreeNode*, kDepth + 1> path_{};
  std::array<bool, kDepth + 1> created_{};
  unsigned valid_;  // path_[top_depth_..valid_] are the previous key's nodes
  bool started_ = false;
  std::uint64_t previous_ = 0;
};

// The chunks' voxels into a walk, free ones with the miss update, hit ones with the hit update.
void walkChunks(TreeWalk& walk, const ChunkUpdate* first, const ChunkUpdate* last, float miss_update,
                float hit_update) {
  static const ChunkWords kNone{};
  for (const ChunkUpdate* chunk = first; chunk != last; ++chunk) {
    const ChunkWords& free_words = chunk->free != nullptr ? *chunk->free : kNone;
    const ChunkWords& hit_words = chunk->hit != nullptr ? *chunk->hit : kNone;
    for (std::size_t w = 0; w < kChunkWords; ++w) {
      const std::uint64_t hits = hit_words[w];
      forEachCode(chunk->code, w, free_words[w] | hits, [&](std::uint64_t key_code) {
        walk.visit(key_code, (hits >> (key_code & 63U)) & 1U ? hit_update : miss_update);
      });
    }
  }
}

std::uint64_t prefixOf(std::uint64_t chunk_code, unsigned depth) { return chunk_code >> (3 * (kChunkDepth - depth)); }

// The shallowest depth with enough subtrees to spread over the threads (dynamic
// scheduling evens out their sizes), no deeper than a chunk's node.
unsigned splitDepth(const std::vector<ChunkUpdate>& chunks, int threads) {
  const std::size_t wanted = 16 * static_cast<std::size_t>(threads);
  for (unsigned depth = 1; depth < kChunkDepth; ++depth) {
    std::size_t subtrees = 1;
    for (std::size_t k = 1; k < chunks.size() && subtrees < wanted; ++k) {
      subtrees += prefixOf(chunks[k].code, depth) != prefixOf(chunks[k - 1].code, depth) ? 1 : 0;
    }
    if (subtrees >= wanted) return depth;
  }
  return kChunkDepth;
}

int threadCount() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

struct Subtree {
  std::size_t first;  // chunks [first, last)
  std::size_t last;
  OcTreeNode* top;
  bool created;
};

OcTreeNode* childOrNull(const OcTreeNode* node, unsigned child) {
  AbstractOcTreeNode** const children = node->*NodeMembers::kChildren;
  return children == nullptr ? nullptr : static_cast<OcTreeNode*>(children[child]);
}

bool hasChildren(const OcTreeNode* node) {
  for (unsigned k = 0; k < 8; ++k) {
    if (childOrNull(node, k) != nullptr) return true;
  }
  return false;
}

// Whether every path above the split either exists or can be created: false when an
// existing node there has no children, a pruned node that only the serial walk expands
// (or not, when saturated) as OctoMap does.
bool splittable(const std::vector<ChunkUpdate>& chunks, unsigned split, const OcTreeNode* root, bool root_created) {
  for (const ChunkUpdate& chunk : chunks) {
    const std::uint64_t code = chunk.code << (3 * kChunkBits);
    const OcTreeNode* node = root;
    bool created = root_created;
    for (unsigned d = 0; d < split && node != nullptr; ++d) {
      const OcTreeNode* child = childOrNull(node, childOf(code, d));
      if (child == nullptr && !created && !hasChildren(node)) return false;
      node = child;
      created = false;
    }
  }
  return true;
}

// The subtrees at the split, with the nodes above it that they need created as the walk
// would create them.
std::vector<Subtree> prepareSubtrees(const std::vector<ChunkUpdate>& chunks, unsigned split, OcTreeNode* root,
                                     bool root_created, NodeEdits& edits) {
  std::vector<Subtree> subtrees;
  for (std::size_t first = 0; first < chunks.size();) {
    const std::uint64_t prefix = prefixOf(chunks[first].code, split);
    std::size_t last = first + 1;
    while (last < chunks.size() && prefixOf(chunks[last].code, split) == prefix) ++last;
    const std::uint64_t code = chunks[first].code << (3 * kChunkBits);
    OcTreeNode* node = root;
    bool created = root_created;
    for (unsigned d = 0; d < split; ++d) {
      OcTreeNode* child = childOrNull(node, childOf(code, d));
      created = child == nullptr;
      node = created ? edits.createChild(node, childOf(code, d)) : child;
    }
    subtrees.push_back(Subtree{first, last, node, created});
    first = last;
  }
  return subtrees;
}

}  // namespace

void updateTree(octomap::OcTree& tree, const std::vector<ChunkUpdate>& chunks, unsigned split_depth) {
  if (chunks.empty()) return;
  const float miss_update = tree.getProbMissLog();
  const float hit_update = tree.getProbHitLog();
  OcTreeNode*& root = tree.*TreeMembers::kRoot;
  std::ptrdiff_t nodes_added = 0;
  bool root_created = false;
  if (root == nullptr) {  // as updateNode creates it
    root = new OcTreeNode();
    root_created = true;
    ++nodes_added;
  }
  const int threads = threadCount();
  const unsigned split = split_depth != 0 ? std::min(split_depth, kChunkDepth) : splitDepth(chunks, threads);
  NodeEdits edits(tree);
  if (splittable(chunks, split, root, root_created)) {
    const std::vector<Subtree> subtrees = prepareSubtrees(chunks, split, root, root_created, edits);
    const auto count = static_cast<std::int64_t>(subtrees.size());
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : nodes_added)
    for (std::int64_t s = 0; s < count; ++s) {
      const Subtree& subtree = subtrees[static_cast<std::size_t>(s)];
      TreeWalk walk(tree, subtree.top, split, subtree.created);
      walkChunks(walk, chunks.data() + subtree.first, chunks.data() + subtree.last, miss_update, hit_update);
      walk.finish();
      nodes_added += walk.nodesAdded();
    }
    // The nodes above the split, deepest first; walking down to them passes only
    // shallower nodes, none pruned yet.
    for (unsigned depth = split; depth-- > 0;) {
      std::uint64_t previous = ~std::uint64_t{0};
      for (const Subtree& subtree : subtrees) {
        const std::uint64_t prefix = prefixOf(chunks[subtree.first].code, depth);
        if (prefix == previous) continue;
        previous = prefix;
        const std::uint64_t code = chunks[subtree.first].code << (3 * kChunkBits);
        OcTreeNode* node = root;
        for (unsigned d = 0; d < depth; ++d) node = tree.getNodeChild(node, childOf(code, d));
        edits.settle(node);
      }
    }
  } else {
    TreeWalk walk(tree, root, 0, root_created);
    walkChunks(walk, chunks.data(), chunks.data() + chunks.size(), miss_update, hit_update);
    walk.finish();
    nodes_added += walk.nodesAdded();
  }
  nodes_added += edits.nodesAdded();
  tree.*TreeMembers::kSize = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(tree.*TreeMembers::kSize) + nodes_added);
  tree.*TreeMembers::kSizeChanged = true;
}

}  // namespace mlmap::detail
