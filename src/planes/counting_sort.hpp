// Internal to eRMSM: a stable sort by an integer key, in linear time.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace mlmap {

// Stably reorders the items by key(item), an integer: a counting sort over the keys'
// range, or a stable comparison sort when that range is far wider than the list (a map
// kilometres long). Sorting by the least significant key first and the most significant
// last orders by all of them. The items move, not indices to them: each pass then reads
// them in order, where looking keys up through indices jumps across memory.
template <typename Item, typename Key>
void stableSortBy(std::vector<Item>& items, Key key) {
  if (items.empty()) return;
  std::int64_t low = key(items[0]);
  std::int64_t high = low;
  for (const Item& item : items) {
    low = std::min<std::int64_t>(low, key(item));
    high = std::max<std::int64_t>(high, key(item));
  }
  const auto range = static_cast<std::size_t>(high - low + 1);
  if (range > 4 * items.size() + 4096) {
    std::stable_sort(items.begin(), items.end(), [&](const Item& a, const Item& b) { return key(a) < key(b); });
    return;
  }
  std::vector<std::uint32_t> first(range + 1, 0);
  for (const Item& item : items) ++first[static_cast<std::size_t>(key(item) - low) + 1];
  for (std::size_t k = 1; k <= range; ++k) first[k] += first[k - 1];
  std::vector<Item> sorted(items.size());
  for (const Item& item : items) sorted[first[static_cast<std::size_t>(key(item) - low)]++] = item;
  items = std::move(sorted);
}

}  // namespace mlmap
