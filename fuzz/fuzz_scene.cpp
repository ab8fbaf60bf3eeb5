// Scene files (`mlmap simulate`, `mlmap emulate`) through sim::loadScene: the file is read,
// its elements checked, its includes (relative ones resolve in the fuzzer's private
// directory, where none exist) placed and its openings cut.
#include "fuzz_support.hpp"
#include "mlmap/sim/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = mlmap::fuzz::inputFiles().write("scene.json", mlmap::fuzz::asText(data, size));
  mlmap::fuzz::refusedOrRead([&] { mlmap::sim::loadScene(path); });
  return 0;
}
