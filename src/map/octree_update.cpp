#include "octree_update.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "key_bits.hpp"
#include "octree_walk.hpp"
#include "omp_threads.hpp"

namespace mlmap::detail {
namespace {

using octomap::OcTreeKey;
using octomap::point3d;

// One axis of a ray's steps through the Morton index of a voxel in its chunk: the
// axis's bits of the index (every third) form the voxel's coordinate in the chunk, and
// a step adds or subtracts one there, leaving the other axes' bits. The step's sign is
// a template argument so that the masks are constants, not registers the ray loop
// runs short of.
template <unsigned Axis, int Step>
struct AxisStep {
  static constexpr unsigned kMask = static_cast<unsigned>(spreadBits((1U << kChunkBits) - 1)) << Axis;
  // +1: the other bits set so that the carry passes them; -1: cleared so that the borrow does
  static constexpr unsigned kKeep = Step > 0 ? ~0U : kMask;
  static constexpr unsigned kFill = Step > 0 ? ~kMask : 0U;
  static constexpr unsigned kAdd = Step > 0 ? 1U << Axis : 0U - (1U << Axis);
  static constexpr unsigned kLeaves = Step > 0 ? kMask : 0U;  // the chunk's last coordinate that way
  static constexpr unsigned kKeyStep = static_cast<unsigned>(Step);

  // Steps the key and the index; true when the step leaves the chunk.
  static bool advance(unsigned& key, unsigned& bit) {
    key = (key + kKeyStep) & 0xFFFFU;  // key_type arithmetic
    const bool wraps = (bit & kMask) == kLeaves;
    bit = ((((bit & kKeep) | kFill) + kAdd) & kMask) | (bit & ~kMask);
    return wraps;
  }
};

struct RayStart {
  std::array<unsigned, 3> key;
  std::array<unsigned, 3> key_end;
  std::array<double, 3> t_max;
  std::array<double, 3> t_delta;
  double length;
};

// computeRayKeys' incremental phase for one combination of step signs (an axis whose
// step is 0 has t = DBL_MAX and is never chosen before the length test ends the ray;
// it takes +1 here). The three t and keys are in registers instead of indexed arrays
// (a store and reload per step), one branch per axis choice (its if/else) so that a
// step adds to one t only, and the key set's bit insert is inlined.
//
// Its test for the end voxel compares the whole key at every step. Each step moves
// one key component one voxel towards the end's side (the step signs are those of
// end - origin, and keys grow with the coordinate), so the end voxel can only be
// reached at step |Δk0| + |Δk1| + |Δk2|, the one step where the key is compared.
//
// The voxel's bit in its chunk is stepped along with the key instead of computed from
// the key at every step; the chunk is looked up again only when a step leaves it.
template <int S0, int S1, int S2>
void stepRay(const RayStart& ray, KeyBits& free) {
  double t0 = ray.t_max[0];
  double t1 = ray.t_max[1];
  double t2 = ray.t_max[2];
  unsigned k0 = ray.key[0];
  unsigned k1 = ray.key[1];
  unsigned k2 = ray.key[2];
  const double delta0 = ray.t_delta[0];
  const double delta1 = ray.t_delta[1];
  const double delta2 = ray.t_delta[2];
  const double length = ray.length;
  const auto distance = [](unsigned a, unsigned b) { return a > b ? a - b : b - a; };
  auto to_end = static_cast<std::int64_t>(distance(k0, ray.key_end[0]) + distance(k1, ray.key_end[1]) +
                                          distance(k2, ray.key_end[2]));
  unsigned bit = KeyBits::bitInChunk(k0, k1, k2);
  ChunkWords* words = nullptr;  // the chunk of bit; null: look it up
  for (;;) {
    bool left_chunk = false;
    if (t0 < t1) {
      if (t0 < t2) {
        t0 += delta0;
        left_chunk = AxisStep<0, S0>::advance(k0, bit);
      } else {
        t2 += delta2;
        left_chunk = AxisStep<2, S2>::advance(k2, bit);
      }
    } else if (t1 < t2) {
      t1 += delta1;
      left_chunk = AxisStep<1, S1>::advance(k1, bit);
    } else {
      t2 += delta2;
      left_chunk = AxisStep<2, S2>::advance(k2, bit);
    }
    if (left_chunk) words = nullptr;
    if (--to_end == 0) [[unlikely]] {
      if (k0 == ray.key_end[0] && k1 == ray.key_end[1] && k2 == ray.key_end[2]) return;
    }
    // Past the end's distance without meeting its voxel: rounding, stop as OctoMap does.
    if (std::min(std::min(t0, t1), t2) > length) return;
    if (words == nullptr) [[unlikely]] words = &free.chunkWords(k0, k1, k2);
    (*words)[bit >> 6U] |= std::uint64_t{1} << (bit & 63U);
  }
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
  const RayStart ray{{key_origin[0], key_origin[1], key_origin[2]},
                     {key_end[0], key_end[1], key_end[2]},
                     t_max,
                     t_delta,
                     length};
  switch ((step[0] < 0 ? 1 : 0) | (step[1] < 0 ? 2 : 0) | (step[2] < 0 ? 4 : 0)) {
    case 0: stepRay<1, 1, 1>(ray, free); break;
    case 1: stepRay<-1, 1, 1>(ray, free); break;
    case 2: stepRay<1, -1, 1>(ray, free); break;
    case 3: stepRay<-1, -1, 1>(ray, free); break;
    case 4: stepRay<1, 1, -1>(ray, free); break;
    case 5: stepRay<-1, 1, -1>(ray, free); break;
    case 6: stepRay<1, -1, -1>(ray, free); break;
    default: stepRay<-1, -1, -1>(ray, free); break;
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

void merge(const std::vector<KeyBits>& sets, MergedBits& merged) {
  merged.codes.clear();
  for (const KeyBits& set : sets) {
    merged.codes.insert(merged.codes.end(), set.chunkCodes().begin(), set.chunkCodes().end());
  }
  std::sort(merged.codes.begin(), merged.codes.end());
  merged.codes.erase(std::unique(merged.codes.begin(), merged.codes.end()), merged.codes.end());
  merged.words.resize(merged.codes.size());
  // On one thread: a few hundred microseconds of ORs per scan, less than a parallel
  // region costs when the machine is shared (see insertRays).
  for (std::size_t c = 0; c < merged.codes.size(); ++c) {
    ChunkWords& out = merged.words[c];
    out.fill(0);
    for (const KeyBits& set : sets) {
      const ChunkWords* in = set.find(merged.codes[c]);
      if (in == nullptr) continue;
      for (std::size_t w = 0; w < kChunkWords; ++w) out[w] |= (*in)[w];
    }
  }
}

// The key sets of one scan, kept on the calling thread for the next: they span
// megabytes, and fresh ones each scan cost page faults and zeroing (12 % of the
// insertion at 5 cm).
struct RayBuffers {
  std::vector<KeyBits> free;
  std::vector<KeyBits> hit;
  std::vector<KeyBits> ends;
  MergedBits merged_free;
  MergedBits merged_hit;
  MergedBits merged_ends;

  // n empty sets each
  void reset(std::size_t n) {
    for (std::vector<KeyBits>* sets : {&free, &hit, &ends}) {
      sets->resize(n);
      for (KeyBits& set : *sets) set.clear();
    }
  }
};

// The free and hit sets side by side, chunk by chunk in ascending code.
std::vector<ChunkUpdate> chunkUpdates(const MergedBits& free, const MergedBits& hit) {
  std::vector<ChunkUpdate> chunks;
  chunks.reserve(std::max(free.codes.size(), hit.codes.size()));
  std::size_t f = 0;
  std::size_t h = 0;
  while (f < free.codes.size() || h < hit.codes.size()) {
    const std::uint64_t code = std::min(f < free.codes.size() ? free.codes[f] : ~std::uint64_t{0},
                                        h < hit.codes.size() ? hit.codes[h] : ~std::uint64_t{0});
    const ChunkWords* free_words = f < free.codes.size() && free.codes[f] == code ? &free.words[f++] : nullptr;
    const ChunkWords* hit_words = h < hit.codes.size() && hit.codes[h] == code ? &hit.words[h++] : nullptr;
    chunks.push_back(ChunkUpdate{code, free_words, hit_words});
  }
  return chunks;
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
  static thread_local RayBuffers buffers;
  buffers.reset(static_cast<std::size_t>(threadCount()));
  std::vector<KeyBits>& free = buffers.free;
  std::vector<KeyBits>& hit = buffers.hit;
  if (options.exact_rays) {
#pragma omp parallel for schedule(dynamic, 4096)
    for (std::int64_t index = 0; index < point_count; ++index) {
      const auto thread = static_cast<std::size_t>(threadIndex());
      castMeasurement(tree, origin, endPoint(index), options.max_range, free[thread], hit[thread]);
    }
  } else {
    // OctoMap's computeDiscreteUpdate: one ray to the centre of each voxel that holds
    // end points (the range limit applies to that centre too).
    //
    // The end voxels on one thread: a parallel region ends when its last thread
    // arrives, and on a machine shared with other jobs the second thread may wait a
    // scheduler time slice (milliseconds) to run at all. Two threads made this step
    // 36 -> 55 ms and the merges 0.5 -> 25 ms at 10 cm on the lab (8 scans, load 4);
    // only the ray casting and the tree update carry enough work per scan to gain.
    std::vector<KeyBits>& end_sets = buffers.ends;
    for (std::int64_t index = 0; index < point_count; ++index) {
      OcTreeKey key;
      if (tree.coordToKeyChecked(endPoint(index), key)) end_sets[0].insert(key);
    }
    const MergedBits& ends = buffers.merged_ends;
    merge(end_sets, buffers.merged_ends);
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
  merge(free, buffers.merged_free);
  merge(hit, buffers.merged_hit);
  updateTree(tree, chunkUpdates(buffers.merged_free, buffers.merged_hit), options.split_depth);
}

}  // namespace mlmap::detail
