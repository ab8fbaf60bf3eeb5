// A set of OcTree voxel keys as bitmaps over 16³-voxel chunks, for the keys one scan
// touches. Rays visit neighbouring voxels one after another, so a set bit costs a shift
// and an OR in the chunk the previous voxel used (one hash look-up per chunk change);
// node-based key sets cost an allocation per key and a serial merge.
//
// Bits inside a chunk and chunks among themselves are numbered in Morton order (x in
// the lowest bit of each triple, as OctoMap's child index), so walking a set's chunks
// in ascending code and each chunk's bits in ascending order visits the keys in the
// order of a depth-first walk of the OcTree.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <vector>

#include <octomap/OcTreeKey.h>

namespace mlmap::detail {

inline constexpr unsigned kChunkBits = 4;  // 16 voxels a side
inline constexpr std::size_t kChunkWords = (std::size_t{1} << (3 * kChunkBits)) / 64;
using ChunkWords = std::array<std::uint64_t, kChunkWords>;

// Spreads the low 16 bits of v to every third bit (bit i -> bit 3i).
constexpr std::uint64_t spreadBits(std::uint64_t v) {
  v &= 0xFFFFU;
  v = (v | (v << 16)) & 0x0000FF0000FFULL;
  v = (v | (v << 8)) & 0x00F00F00F00FULL;
  v = (v | (v << 4)) & 0x0C30C30C30C3ULL;
  v = (v | (v << 2)) & 0x249249249249ULL;
  return v;
}

constexpr std::uint64_t compactBits(std::uint64_t v) {
  v &= 0x249249249249ULL;
  v = (v | (v >> 2)) & 0x0C30C30C30C3ULL;
  v = (v | (v >> 4)) & 0x00F00F00F00FULL;
  v = (v | (v >> 8)) & 0x0000FF0000FFULL;
  v = (v | (v >> 16)) & 0xFFFFU;
  return v;
}

// The 48-bit Morton code of a key and back.
inline std::uint64_t mortonOf(const octomap::OcTreeKey& key) {
  return spreadBits(key[0]) | (spreadBits(key[1]) << 1) | (spreadBits(key[2]) << 2);
}
inline octomap::OcTreeKey keyOfMorton(std::uint64_t code) {
  return octomap::OcTreeKey(static_cast<octomap::key_type>(compactBits(code)),
                            static_cast<octomap::key_type>(compactBits(code >> 1)),
                            static_cast<octomap::key_type>(compactBits(code >> 2)));
}

// Calls visit(code) for the Morton code of every set bit of word `word` (`bits`) of the
// chunk with code `chunk_code`, in ascending order.
template <typename Visit>
void forEachCode(std::uint64_t chunk_code, std::size_t word, std::uint64_t bits, Visit&& visit) {
  while (bits != 0) {
    const auto bit = static_cast<std::uint64_t>(std::countr_zero(bits));
    bits &= bits - 1;
    visit((chunk_code << (3 * kChunkBits)) | (word * 64 + bit));
  }
}

class KeyBits {
 public:
  KeyBits() : slots_(64, 0), slot_index_(64, 0) {}

  // Inlined into the ray loop; the chunk change (one step in ~16) is not.
  [[gnu::always_inline]] void insert(unsigned x, unsigned y, unsigned z) {
    const std::uint64_t chunk = chunkOf(x, y, z);
    if (chunk != cached_chunk_) [[unlikely]] switchChunk(chunk);
    const unsigned mask = (1U << kChunkBits) - 1;
    const unsigned bit = kInChunk[x & mask] | (kInChunk[y & mask] << 1) | (kInChunk[z & mask] << 2);
    (*cached_words_)[bit >> 6] |= std::uint64_t{1} << (bit & 63U);
  }
  void insert(const octomap::OcTreeKey& key) { insert(key[0], key[1], key[2]); }

  // The words of the chunk holding key (x, y, z), added if new; valid until the next
  // chunk is added. With bitInChunk, for callers that step through a chunk themselves.
  ChunkWords& chunkWords(unsigned x, unsigned y, unsigned z) {
    const std::uint64_t chunk = chunkOf(x, y, z);
    if (chunk != cached_chunk_) switchChunk(chunk);
    return *cached_words_;
  }
  // The Morton index of key (x, y, z) in its chunk.
  static unsigned bitInChunk(unsigned x, unsigned y, unsigned z) {
    const unsigned mask = (1U << kChunkBits) - 1;
    return kInChunk[x & mask] | (kInChunk[y & mask] << 1) | (kInChunk[z & mask] << 2);
  }

  // Empties the set, keeping its memory for the next scan.
  void clear() {
    std::fill(slots_.begin(), slots_.end(), 0);
    codes_.clear();
    words_.clear();
    cached_chunk_ = ~std::uint64_t{0};
    cached_words_ = nullptr;
  }

  // The chunks in the order they were first touched, by Morton code of the chunk.
  const std::vector<std::uint64_t>& chunkCodes() const { return codes_; }
  const ChunkWords& chunkAt(std::size_t index) const { return words_[index]; }
  // The words of the chunk with this code, or nullptr.
  const ChunkWords* find(std::uint64_t code) const {
    const std::uint64_t chunk = compactBits(code) | (compactBits(code >> 1) << 16) | (compactBits(code >> 2) << 32);
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t s = hashOf(chunk) & mask;; s = (s + 1) & mask) {
      if (slots_[s] == 0) return nullptr;
      if (slots_[s] == chunk + 1) return &words_[slot_index_[s]];
    }
  }

 private:
  static constexpr std::array<unsigned, 1U << kChunkBits> kInChunk = [] {
    std::array<unsigned, 1U << kChunkBits> table{};
    for (unsigned v = 0; v < table.size(); ++v) table[v] = static_cast<unsigned>(spreadBits(v));
    return table;
  }();

  // The chunk's coordinates, packed (the cache's key).
  static std::uint64_t chunkOf(unsigned x, unsigned y, unsigned z) {
    return (x >> kChunkBits) | (static_cast<std::uint64_t>(y >> kChunkBits) << 16) |
           (static_cast<std::uint64_t>(z >> kChunkBits) << 32);
  }

  // The table is keyed by the packed chunk coordinates, the key the cache compares,
  // so that a chunk change (one per ~10 ray steps) spreads no bits; a chunk's Morton
  // code is computed once, when it is added.
  [[gnu::noinline]] void switchChunk(std::uint64_t chunk) {
    cached_chunk_ = chunk;
    cached_words_ = &words_[chunkIndex(chunk)];
  }

  static std::size_t hashOf(std::uint64_t chunk) {
    return static_cast<std::size_t>((chunk * 0x9E3779B97F4A7C15ULL) >> 40);
  }

  std::size_t chunkIndex(std::uint64_t chunk) {
    std::size_t mask = slots_.size() - 1;
    for (std::size_t s = hashOf(chunk) & mask;; s = (s + 1) & mask) {
      if (slots_[s] == chunk + 1) return slot_index_[s];
      if (slots_[s] != 0) continue;
      if (2 * (codes_.size() + 1) > slots_.size()) {
        grow();
        mask = slots_.size() - 1;
        s = hashOf(chunk) & mask;
        while (slots_[s] != 0) s = (s + 1) & mask;
      }
      slots_[s] = chunk + 1;
      slot_index_[s] = static_cast<std::uint32_t>(codes_.size());
      codes_.push_back(spreadBits(chunk & 0xFFFFU) | (spreadBits((chunk >> 16) & 0xFFFFU) << 1) |
                       (spreadBits(chunk >> 32) << 2));
      words_.emplace_back();
      return codes_.size() - 1;
    }
  }

  void grow() {
    std::vector<std::uint64_t> old_slots(slots_.size() * 2, 0);
    std::vector<std::uint32_t> old_index(slots_.size() * 2, 0);
    old_slots.swap(slots_);
    old_index.swap(slot_index_);
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t old = 0; old < old_slots.size(); ++old) {
      if (old_slots[old] == 0) continue;
      std::size_t s = hashOf(old_slots[old] - 1) & mask;
      while (slots_[s] != 0) s = (s + 1) & mask;
      slots_[s] = old_slots[old];
      slot_index_[s] = old_index[old];
    }
  }

  std::vector<std::uint64_t> slots_;       // packed chunk coordinates (chunkOf) + 1; 0 = empty
  std::vector<std::uint32_t> slot_index_;  // index into codes_ and words_
  std::vector<std::uint64_t> codes_;
  std::vector<ChunkWords> words_;
  std::uint64_t cached_chunk_ = ~std::uint64_t{0};
  ChunkWords* cached_words_ = nullptr;
};

}  // namespace mlmap::detail
