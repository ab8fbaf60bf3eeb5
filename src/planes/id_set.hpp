// Internal to eRMSM: a set of block ids as a bitmap over all ids. Membership costs one
// bit test, and the members come out ascending in one pass over the words (up to the
// last member): sorting the 150 000 ids of a floor at 2 cm cost more than the rest of
// its acceptance.
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

namespace mlmap {

class IdSet {
 public:
  explicit IdSet(std::size_t universe) : words_((universe + 63) / 64, 0) {}

  bool contains(std::uint32_t id) const { return ((words_[id >> 6] >> (id & 63U)) & 1U) != 0; }
  void insert(std::uint32_t id) {
    std::uint64_t& word = words_[id >> 6];
    const std::uint64_t bit = std::uint64_t{1} << (id & 63U);
    // Counted as they come: a count of the words' bits at the end took a call per word
    // (no popcount instruction without -march), the whole cost for a small plane's set.
    count_ += (word & bit) == 0 ? 1 : 0;
    word |= bit;
  }

  std::vector<std::uint32_t> ascending() const {
    // Reserved whole: a floor's 150 000 ids grown by doubling touched twice the memory.
    std::vector<std::uint32_t> ids;
    ids.reserve(count_);
    for (std::size_t w = 0; w < words_.size() && ids.size() < count_; ++w) {
      for (std::uint64_t word = words_[w]; word != 0; word &= word - 1) {
        ids.push_back(static_cast<std::uint32_t>(64 * w + static_cast<std::size_t>(std::countr_zero(word))));
      }
    }
    return ids;
  }

 private:
  std::vector<std::uint64_t> words_;
  std::size_t count_ = 0;
};

}  // namespace mlmap
