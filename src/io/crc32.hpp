// CRC-32 (IEEE 802.3, as zlib and PNG compute it), for file checksums.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace mlmap::io {

inline std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc = 0) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> entries{};
    for (std::uint32_t n = 0; n < 256; ++n) {
      std::uint32_t c = n;
      for (int bit = 0; bit < 8; ++bit) c = (c & 1U) ? 0xEDB88320U ^ (c >> 1) : c >> 1;
      entries[n] = c;
    }
    return entries;
  }();
  const auto* bytes = static_cast<const unsigned char*>(data);
  crc = ~crc;
  for (std::size_t k = 0; k < size; ++k) crc = table[(crc ^ bytes[k]) & 0xFFU] ^ (crc >> 8);
  return ~crc;
}

}  // namespace mlmap::io
