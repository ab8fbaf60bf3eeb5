// 3DTK scans through io::readThreeDtkScan, which reads scanNNN.3d and its scanNNN.pose.
// The input is the .3d text, a NUL byte, then the .pose text; without a NUL there is
// no .pose file at all.
#include <filesystem>

#include "fuzz_support.hpp"
#include "mlmap/io/threedtk.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input = mlmap::fuzz::asText(data, size);
  const auto split = input.find('\0');
  const auto& files = mlmap::fuzz::inputFiles();
  const auto path = files.write("scan000.3d", input.substr(0, split));
  if (split == std::string_view::npos) {
    std::filesystem::remove(std::filesystem::path(path).replace_extension(".pose"));
  } else {
    files.write("scan000.pose", input.substr(split + 1));
  }
  mlmap::fuzz::refusedOrRead([&] { mlmap::io::readThreeDtkScan(path); });
  return 0;
}
