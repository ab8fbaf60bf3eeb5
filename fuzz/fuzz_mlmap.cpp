// .mlmap files through io::readMap. Nearly every mutation of a map breaks its CRC-32,
// which the reader checks first, so the input is the file without its checksum and the
// right one is appended here: the fuzzer then reaches the header, the cells, the blocks
// and the embedded OcTree. (A wrong checksum is one comparison, covered by the tests.)
#include <cstring>

#include "crc32.hpp"
#include "fuzz_support.hpp"
#include "mlmap/io/map_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string bytes(mlmap::fuzz::asText(data, size));
  const std::uint32_t crc = mlmap::io::crc32(bytes.data(), bytes.size());
  char stored[4];
  std::memcpy(stored, &crc, sizeof(crc));  // little-endian hosts only, as the format
  bytes.append(stored, sizeof(stored));
  const auto path = mlmap::fuzz::inputFiles().write("input.mlmap", bytes);
  mlmap::fuzz::refusedOrRead([&] { mlmap::io::readMap(path); });
  return 0;
}
