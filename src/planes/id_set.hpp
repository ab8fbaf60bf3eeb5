// Internal to eRMSM: a set of block ids as a bitmap over all ids. Membership costs one
// bit test, and the members come out ascending in one pass over the words: sorting the
// 150 000 ids of a floor at 2 cm cost more than the rest of its acceptance.
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

namespace mlmap {

class IdSet {
 public:
  explicit IdSet(std::size_t universe) : words_((universe + 63) / 64, 0) {}

  bool contains(std::uint32_t id) const { return ((words_[id >> 6] >> (id & 63U)) & 1U) != 0; }
  void insert(std::uint32_t id) { words_[id >> 6] |= std::uint64_t{1} << (id & 63U); }

  std::vector<std::uint32_t> ascending() const {
    std::size_t count = 0;
    for (const std::uint64_t word : words_) count += static_cast<std::size_t>(std::popcount(word));
    // Reserved whole: a floor's 150 000 ids grown by doubling touched twice the memory.
    std::vector<std::uint32_t> ids;
    ids.reserve(count);
    for (std::size_t w = 0; w < words_.size(); ++w) {
      for (std::uint64_t word = words_[w]; word != 0; word &= word - 1) {
        ids.push_back(static_cast<std::uint32_t>(64 * w + static_cast<std::size_t>(std::countr_zero(word))));
      }
    }
    return ids;
  }

 private:
  std::vector<std::uint64_t> words_;
};

}  // namespace mlmap
