#include "octree_update.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "key_bits.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap::detail {
namespace {

using octomap::OcTreeKey;
using octomap::point3d;

int threadCount() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

int threadIndex() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

// OcTreeBaseImpl::computeRayKeys (Amanatides & Woo's DDA) step for step, with the same
// float and double operations so that it visits the same voxels, into a KeyBits
// instead of a KeyRay: the voxels from the origin's up to, not including, the end's.
void castRay(const octomap::OcTree& tree, const point3d& origin, const point3d& end, KeyBits& free) {
  OcTreeKey key_origin;
  OcTreeKey key_end;
  if (!tree.coordToKeyChecked(origin, key_origin) || !tree.coordToKeyChecked(end, key_end)) return;
  if (key_origin == key_end) return;
  free.insert(key_origin);
  point3d direction = end - origin;
  const auto length = static_cast<float>(direction.norm());
  direction /= length;
  const double resolution = tree.getResolution();
  std::array<int, 3> step{};
  std::array<double, 3> t_max{};
  std::array<double, 3> t_delta{};
  for (unsigned i = 0; i < 3; ++i) {
    if (direction(i) > 0.0) {
      step[i] = 1;
    } else if (direction(i) < 0.0) {
      step[i] = -1;
    }
    if (step[i] != 0) {
      double border = tree.keyToCoord(key_origin[i]);
      border += static_cast<float>(step[i] * resolution * 0.5);
      t_max[i] = (border - origin(i)) / direction(i);
      t_delta[i] = resolution / std::fabs(direction(i));
    } else {
      t_max[i] = std::numeric_limits<double>::max();
      t_delta[i] = std::numeric_limits<double>::max();
    }
  }
  std::array<unsigned, 3> key{key_origin[0], key_origin[1], key_origin[2]};
  for (;;) {
    unsigned dim = 0;
    if (t_max[0] < t_max[1]) {
      dim = t_max[0] < t_max[2] ? 0 : 2;
    } else {
      dim = t_max[1] < t_max[2] ? 1 : 2;
    }
    key[dim] = (key[dim] + static_cast<unsigned>(step[dim])) & 0xFFFFU;  // key_type arithmetic
    t_max[dim] += t_delta[dim];
    if (key[0] == key_end[0] && key[1] == key_end[1] && key[2] == key_end[2]) return;
    // Past the end's distance without meeting its voxel: rounding, stop as OctoMap does.
    if (std::min(std::min(t_max[0], t_max[1]), t_max[2]) > length) return;
    free.insert(key[0], key[1], key[2]);
  }
}

// One measurement as OccupancyOcTreeBase::computeUpdate takes it.
void castMeasurement(const octomap::OcTree& tree, const point3d& origin, const point3d& end, double max_range,
                     KeyBits& free, KeyBits& hit) {
  if (max_range < 0.0 || (end - origin).norm() <= max_range) {
    castRay(tree, origin, end, free);
    OcTreeKey key;
    if (tree.coordToKeyChecked(end, key)) hit.insert(key);
  } else {
    castRay(tree, origin, origin + (end - origin).normalized() * static_cast<float>(max_range), free);
  }
}

// The union of the threads' sets: chunks in ascending Morton code.
struct MergedBits {
  std::vector<std::uint64_t> codes;
  std::vector<ChunkWords> words;
};

MergedBits merge(const std::vector<KeyBits>& sets) {
  MergedBits merged;
  for (const KeyBits& set : sets) {
    merged.codes.insert(merged.codes.end(), set.chunkCodes().begin(), set.chunkCodes().end());
  }
  std::sort(merged.codes.begin(), merged.codes.end());
  merged.codes.erase(std::unique(merged.codes.begin(), merged.codes.end()), merged.codes.end());
  merged.words.resize(merged.codes.size());
  const auto chunk_count = static_cast<std::int64_t>(merged.codes.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t c = 0; c < chunk_count; ++c) {
    ChunkWords& out = merged.words[static_cast<std::size_t>(c)];
    out.fill(0);
    for (const KeyBits& set : sets) {
      const ChunkWords* in = set.find(merged.codes[static_cast<std::size_t>(c)]);
      if (in == nullptr) continue;
      for (std::size_t w = 0; w < kChunkWords; ++w) out[w] |= (*in)[w];
    }
  }
  return merged;
}

template <typename Visit>
void forEachCode(std::uint64_t chunk_code, std::size_t word, std::uint64_t bits, Visit&& visit) {
  while (bits != 0) {
    const auto bit = static_cast<std::uint64_t>(std::countr_zero(bits));
    bits &= bits - 1;
    visit((chunk_code << (3 * kChunkBits)) | (word * 64 + bit));
  }
}

// Updates the tree one key at a time in Morton (depth-first) order, keeping the path
// of the previous key: a key descends only from the deepest node it shares with the
// previous one, and an inner node is brought up to date (or pruned) once, when the
// walk leaves it. Each step is the one OccupancyOcTreeBase::updateNodeRecurs takes.
class TreeWalk {
 public:
  explicit TreeWalk(octomap::OcTree& tree) : tree_(tree) {}

  void visit(std::uint64_t code, float update) {
    if (!started_) {
      started_ = true;
      if (tree_.getRoot() == nullptr) {  // only updateNode may create the root
        tree_.updateNode(keyOfMorton(code), update, true);
        path_[0] = tree_.getRoot();
        for (unsigned d = 0; d < kDepth; ++d) path_[d + 1] = tree_.getNodeChild(path_[d], childOf(code, d));
        valid_ = kDepth;
        previous_ = code;
        return;
      }
      path_[0] = tree_.getRoot();
      created_[0] = false;
      valid_ = 0;
    } else {
      const auto group = static_cast<unsigned>(63 - std::countl_zero(code ^ previous_)) / 3;
      close(kDepth - 1 - group);
    }
    previous_ = code;
    for (unsigned d = valid_; d < kDepth; ++d) {
      octomap::OcTreeNode* node = path_[d];
      const unsigned child = childOf(code, d);
      created_[d + 1] = false;
      if (!tree_.nodeChildExists(node, child)) {
        if (!tree_.nodeHasChildren(node) && !created_[d]) {
          // A pruned node: updateNode's early abort leaves it whole when saturated.
          if (saturated(*node, update)) {
            valid_ = d;
            return;
          }
          tree_.expandNode(node);
        } else {
          tree_.createNodeChild(node, child);
          created_[d + 1] = true;
        }
      }
      path_[d + 1] = tree_.getNodeChild(node, child);
    }
    valid_ = kDepth;
    if (!saturated(*path_[kDepth], update)) tree_.updateNodeLogOdds(path_[kDepth], update);
  }

  // Brings the nodes still on the path up to date, the root last.
  void finish() {
    if (!started_) return;
    close(0);
    settle(path_[0]);
  }

 private:
  static constexpr unsigned kDepth = 16;

  static unsigned childOf(std::uint64_t code, unsigned depth) {
    return static_cast<unsigned>(code >> (3 * (kDepth - 1 - depth))) & 7U;
  }

  bool saturated(const octomap::OcTreeNode& node, float update) const {
    return (update >= 0 && node.getLogOdds() >= tree_.getClampingThresMaxLog()) ||
           (update <= 0 && node.getLogOdds() <= tree_.getClampingThresMinLog());
  }

  void settle(octomap::OcTreeNode* node) {
    if (!tree_.nodeHasChildren(node)) return;
    if (!tree_.pruneNode(node)) node->updateOccupancyChildren();
  }

  // Leaves the nodes deeper than `depth`, deepest first.
  void close(unsigned depth) {
    for (; valid_ > depth; --valid_) {
      if (valid_ < kDepth) settle(path_[valid_]);
    }
  }

  octomap::OcTree& tree_;
  std::array<octomap::OcTreeNode*, kDepth + 1> path_{};
  std::array<bool, kDepth + 1> created_{};
  unsigned valid_ = 0;  // path_[0..valid_] are the previous key's nodes
  bool started_ = false;
  std::uint64_t previous_ = 0;
};

// Free voxels minus hit ones with the miss update, hit ones with the hit update, in
// ascending Morton code.
void updateTree(octomap::OcTree& tree, const MergedBits& free, const MergedBits& hit) {
  TreeWalk walk(tree);
  const float miss_update = tree.getProbMissLog();
  const float hit_update = tree.getProbHitLog();
  static const ChunkWords kNone{};
  std::size_t f = 0;
  std::size_t h = 0;
  while (f < free.codes.size() || h < hit.codes.size()) {
    const std::uint64_t code = std::min(f < free.codes.size() ? free.codes[f] : ~std::uint64_t{0},
                                        h < hit.codes.size() ? hit.codes[h] : ~std::uint64_t{0});
    const ChunkWords& free_words = f < free.codes.size() && free.codes[f] == code ? free.words[f++] : kNone;
    const ChunkWords& hit_words = h < hit.codes.size() && hit.codes[h] == code ? hit.words[h++] : kNone;
    for (std::size_t w = 0; w < kChunkWords; ++w) {
      const std::uint64_t hits = hit_words[w];
      forEachCode(code, w, free_words[w] | hits, [&](std::uint64_t key_code) {
        walk.visit(key_code, (hits >> (key_code & 63U)) & 1U ? hit_update : miss_update);
      });
    }
  }
  walk.finish();
}

}  // namespace

void insertRays(octomap::OcTree& tree, const Scan& scan, const RayOptions& options) {
  const Eigen::Vector3d sensor = scan.pose.translation();
  const point3d origin(static_cast<float>(sensor.x()), static_cast<float>(sensor.y()),
                       static_cast<float>(sensor.z()));
  const auto point_count = static_cast<std::int64_t>(scan.size());
  const auto endPoint = [&scan](std::int64_t index) {
    const Eigen::Vector3d world = scan.worldPoint(static_cast<std::size_t>(index));
    return point3d(static_cast<float>(world.x()), static_cast<float>(world.y()), static_cast<float>(world.z()));
  };
  const auto threads = static_cast<std::size_t>(threadCount());
  std::vector<KeyBits> free(threads);
  std::vector<KeyBits> hit(threads);
  if (options.exact_rays) {
#pragma omp parallel for schedule(dynamic, 4096)
    for (std::int64_t index = 0; index < point_count; ++index) {
      const auto thread = static_cast<std::size_t>(threadIndex());
      castMeasurement(tree, origin, endPoint(index), options.max_range, free[thread], hit[thread]);
    }
  } else {
    // OctoMap's computeDiscreteUpdate: one ray to the centre of each voxel that holds
    // end points (the range limit applies to that centre too).
    MergedBits ends;
    {
      std::vector<KeyBits> end_sets(threads);
#pragma omp parallel for schedule(static)
      for (std::int64_t index = 0; index < point_count; ++index) {
        OcTreeKey key;
        if (tree.coordToKeyChecked(endPoint(index), key)) end_sets[static_cast<std::size_t>(threadIndex())].insert(key);
      }
      ends = merge(end_sets);
    }
    const auto chunk_count = static_cast<std::int64_t>(ends.codes.size());
#pragma omp parallel for schedule(dynamic, 4)
    for (std::int64_t c = 0; c < chunk_count; ++c) {
      const auto thread = static_cast<std::size_t>(threadIndex());
      const ChunkWords& words = ends.words[static_cast<std::size_t>(c)];
      for (std::size_t w = 0; w < kChunkWords; ++w) {
        forEachCode(ends.codes[static_cast<std::size_t>(c)], w, words[w], [&](std::uint64_t code) {
          castMeasurement(tree, origin, tree.keyToCoord(keyOfMorton(code)), options.max_range, free[thread],
                          hit[thread]);
        });
      }
    }
  }
  updateTree(tree, merge(free), merge(hit));
}

}  // namespace mlmap::detail
