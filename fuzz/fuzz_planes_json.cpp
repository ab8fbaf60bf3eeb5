// The planes JSON export read back through io::parsePlanesJson (in memory).
#include "fuzz_support.hpp"
#include "mlmap/io/planes_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  mlmap::fuzz::refusedOrRead(
      [&] { mlmap::io::parsePlanesJson(mlmap::fuzz::asText(data, size), "input.json"); });
  return 0;
}
