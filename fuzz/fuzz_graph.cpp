// OctoMap scan graphs, binary and plain ASCII, through io::readScanGraph.
#include "fuzz_support.hpp"
#include "mlmap/io/scan_graph.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = mlmap::fuzz::inputFiles().write("input.graph", mlmap::fuzz::asText(data, size));
  mlmap::fuzz::refusedOrRead([&] { mlmap::io::readScanGraph(path); });
  return 0;
}
