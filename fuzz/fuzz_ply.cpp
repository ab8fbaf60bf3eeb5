// PLY, ascii and binary_little_endian, through io::readPly.
#include "fuzz_support.hpp"
#include "mlmap/io/ply.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = mlmap::fuzz::inputFiles().write("input.ply", mlmap::fuzz::asText(data, size));
  mlmap::fuzz::refusedOrRead([&] { mlmap::io::readPly(path); });
  return 0;
}
