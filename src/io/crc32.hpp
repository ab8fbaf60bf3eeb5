// CRC-32 (IEEE 802.3, as zlib and PNG compute it), for file checksums.
#pragma once

#include <cstddef>
#include <cstdint>

namespace mlmap::io {

// `crc` is the value of the bytes before `data`, so that a checksum can be taken in pieces.
std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc = 0);

}  // namespace mlmap::io
