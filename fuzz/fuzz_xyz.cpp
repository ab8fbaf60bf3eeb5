// XYZ text scans through io::readXyz.
#include "fuzz_support.hpp"
#include "mlmap/io/xyz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = mlmap::fuzz::inputFiles().write("input.xyz", mlmap::fuzz::asText(data, size));
  mlmap::fuzz::refusedOrRead([&] { mlmap::io::readXyz(path); });
  return 0;
}
