// A voxel table: integer voxel coordinates -> a dense index (0, 1, 2, ... in insertion order),
// so the voxels' payload can live in one plain vector beside it. Open addressing with linear
// probing in one flat array: a lookup is a multiply and, mostly, one cache line, where
// std::unordered_map chases a node pointer per bucket. The ICP's neighbour search and the
// down-sampling do little else than look voxels up.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "mlmap/scan.hpp"

namespace mlmap::registration {

struct VoxelKey {
  std::int32_t x = 0, y = 0, z = 0;
  bool operator==(const VoxelKey&) const = default;
};

// The voxel of size 1/`inverse_size` holding `point`: floor of each coordinate over the size,
// clamped to the int32 range (a point that far off is garbage either way; the clamp keeps the
// conversion defined). Floor by truncation: std::floor is a library call without SSE4.1, and
// this runs for every point and every query.
inline VoxelKey voxelKeyOf(const Point& point, double inverse_size) {
  const auto axis = [inverse_size](double c) {
    constexpr double kLimit = 2.0e9;
    const double scaled = std::clamp(c * inverse_size, -kLimit, kLimit);
    const auto truncated = static_cast<std::int32_t>(scaled);
    return static_cast<double>(truncated) > scaled ? truncated - 1 : truncated;
  };
  return {axis(point.x()), axis(point.y()), axis(point.z())};
}

class VoxelTable {
 public:
  static constexpr std::uint32_t kMissing = std::numeric_limits<std::uint32_t>::max();

  // Room for `voxels` entries without rehashing.
  void reserve(std::size_t voxels) {
    std::size_t capacity = 16;
    while (capacity < 2 * voxels) capacity *= 2;  // load factor at most 1/2: short probes
    if (capacity > slots_.size()) rehash(capacity);
    keys_.reserve(voxels);
  }

  // The index of `key`, or kMissing.
  std::uint32_t find(const VoxelKey& key) const {
    if (slots_.empty()) return kMissing;
    for (std::size_t s = slotOf(key);; s = (s + 1) & mask_) {
      const std::uint32_t index = slots_[s];
      if (index == kMissing || keys_[index] == key) return index;
    }
  }

  // The index of `key` and whether it was new; a new key gets index size().
  std::pair<std::uint32_t, bool> insert(const VoxelKey& key) {
    if (2 * (keys_.size() + 1) > slots_.size()) rehash(std::max<std::size_t>(16, 2 * slots_.size()));
    for (std::size_t s = slotOf(key);; s = (s + 1) & mask_) {
      const std::uint32_t index = slots_[s];
      if (index == kMissing) {
        slots_[s] = static_cast<std::uint32_t>(keys_.size());
        keys_.push_back(key);
        return {slots_[s], true};
      }
      if (keys_[index] == key) return {index, false};
    }
  }

  std::size_t size() const { return keys_.size(); }
  // The key of entry `index` (< size()).
  const VoxelKey& key(std::uint32_t index) const { return keys_[index]; }

 private:
  std::size_t slotOf(const VoxelKey& key) const {
    // Three large odd multipliers mix the axes, a Fibonacci multiply spreads the result
    // over the high bits, which index the power-of-two table.
    const std::uint64_t mixed = static_cast<std::uint64_t>(static_cast<std::uint32_t>(key.x)) * 73856093u ^
                                static_cast<std::uint64_t>(static_cast<std::uint32_t>(key.y)) * 19349663u ^
                                static_cast<std::uint64_t>(static_cast<std::uint32_t>(key.z)) * 83492791u;
    return static_cast<std::size_t>((mixed * 0x9E3779B97F4A7C15ull) >> shift_);
  }

  void rehash(std::size_t capacity) {
    slots_.assign(capacity, kMissing);
    mask_ = capacity - 1;
    shift_ = 64;
    for (std::size_t c = capacity; c > 1; c /= 2) --shift_;
    for (std::size_t index = 0; index < keys_.size(); ++index) {
      std::size_t s = slotOf(keys_[index]);
      while (slots_[s] != kMissing) s = (s + 1) & mask_;
      slots_[s] = static_cast<std::uint32_t>(index);
    }
  }

  // Slots hold only indices (4 bytes: the table stays small enough for the cache); the
  // keys, compared on a hit, live in insertion order beside them.
  std::vector<std::uint32_t> slots_;
  std::vector<VoxelKey> keys_;
  std::size_t mask_ = 0;
  int shift_ = 64;
};

}  // namespace mlmap::registration
