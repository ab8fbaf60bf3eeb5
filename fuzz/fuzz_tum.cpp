// TUM pose lists through io::readTumPoses.
#include "fuzz_support.hpp"
#include "mlmap/io/tum_poses.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = mlmap::fuzz::inputFiles().write("poses.txt", mlmap::fuzz::asText(data, size));
  mlmap::fuzz::refusedOrRead([&] { mlmap::io::readTumPoses(path); });
  return 0;
}
