// Internal to eRMSM: a stable sort by an integer key, in linear time.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace mlmap {

// The counting sort's placement: item n of `count`, whose bucket is bucket(n) in
// [0, buckets), goes to place(n, position), its position in the buckets laid end to end,
// the items of a bucket in their order. With `slices` > 1 the items are counted and
// placed in as many contiguous slices on OpenMP threads at once: a bucket's items from
// an earlier slice go first, so the positions are the same.
template <typename Bucket, typename Place>
void placeStably(std::size_t count, std::size_t buckets, Bucket bucket, Place place, int slices = 1) {
  slices = std::max(slices, 1);
  // next[slice × buckets + b]: where the slice's next item of bucket b goes.
  std::vector<std::uint32_t> next(static_cast<std::size_t>(slices) * buckets, 0);
  const auto total = static_cast<std::int64_t>(count);
  auto sliceBegin = [&](int slice) { return static_cast<std::size_t>(total * slice / slices); };
#pragma omp parallel for schedule(static, 1) num_threads(slices) if (slices > 1)
  for (int slice = 0; slice < slices; ++slice) {
    std::uint32_t* counts = next.data() + static_cast<std::size_t>(slice) * buckets;
    for (std::size_t n = sliceBegin(slice); n < sliceBegin(slice + 1); ++n) ++counts[bucket(n)];
  }
  std::uint32_t placed = 0;
  for (std::size_t b = 0; b < buckets; ++b) {
    for (int slice = 0; slice < slices; ++slice) {
      std::uint32_t& slot = next[static_cast<std::size_t>(slice) * buckets + b];
      const std::uint32_t members = slot;
      slot = placed;
      placed += members;
    }
  }
#pragma omp parallel for schedule(static, 1) num_threads(slices) if (slices > 1)
  for (int slice = 0; slice < slices; ++slice) {
    std::uint32_t* positions = next.data() + static_cast<std::size_t>(slice) * buckets;
    for (std::size_t n = sliceBegin(slice); n < sliceBegin(slice + 1); ++n) place(n, positions[bucket(n)]++);
  }
}

// Stably reorders the items by key(item), an integer: a counting sort over the keys'
// range, or a stable comparison sort when that range is far wider than the list (a map
// kilometres long). Sorting by the least significant key first and the most significant
// last orders by all of them. The items move, not indices to them: each pass then reads
// them in order, where looking keys up through indices jumps across memory.
//
// With `threads` > 1 a long list is counted and placed in as many contiguous slices at
// once: a key's items from an earlier slice go first, so the order is the same.
template <typename Item, typename Allocator, typename Key>
void stableSortBy(std::vector<Item, Allocator>& items, Key key, int threads = 1) {
  if (items.empty()) return;
  constexpr std::size_t kParallelItems = 50000;
  const auto count = static_cast<std::int64_t>(items.size());
  const int slices = threads > 1 && items.size() >= kParallelItems ? threads : 1;
  std::int64_t low = key(items[0]);
  std::int64_t high = low;
#pragma omp parallel for schedule(static) num_threads(slices) if (slices > 1) reduction(min : low) reduction(max : high)
  for (std::int64_t n = 0; n < count; ++n) {
    const std::int64_t k = key(items[static_cast<std::size_t>(n)]);
    low = std::min(low, k);
    high = std::max(high, k);
  }
  const auto range = static_cast<std::size_t>(high - low + 1);
  if (range > 4 * items.size() + 4096) {
    std::stable_sort(items.begin(), items.end(), [&](const Item& a, const Item& b) { return key(a) < key(b); });
    return;
  }
  // Every slot is written below (with a FillVector's allocator, not zeroed first).
  std::vector<Item, Allocator> sorted(items.size());
  placeStably(
      items.size(), range, [&](std::size_t n) { return static_cast<std::size_t>(key(items[n]) - low); },
      [&](std::size_t n, std::uint32_t position) { sorted[position] = items[n]; }, slices);
  items = std::move(sorted);
}

}  // namespace mlmap
