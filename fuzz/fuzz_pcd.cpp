// PCD in all three encodings (binary_compressed: LZF) through io::readPcd.
#include "fuzz_support.hpp"
#include "mlmap/io/pcd.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = mlmap::fuzz::inputFiles().write("input.pcd", mlmap::fuzz::asText(data, size));
  mlmap::fuzz::refusedOrRead([&] { mlmap::io::readPcd(path); });
  return 0;
}
