#include "mlmap/io/dashboard.hpp"

#include <system_error>

#include "file_bytes.hpp"
#include "mlmap/error.hpp"

namespace mlmap::io {

std::string base64(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t k = 0;
  for (; k + 3 <= bytes.size(); k += 3) {
    const std::uint32_t triple = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[k])) << 16 |
                                 static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[k + 1])) << 8 |
                                 static_cast<unsigned char>(bytes[k + 2]);
    for (const int shift : {18, 12, 6, 0}) out += kAlphabet[(triple >> shift) & 63];
  }
  if (const std::size_t left = bytes.size() - k; left > 0) {
    std::uint32_t triple = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[k])) << 16;
    if (left == 2) triple |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[k + 1])) << 8;
    out += kAlphabet[(triple >> 18) & 63];
    out += kAlphabet[(triple >> 12) & 63];
    out += left == 2 ? kAlphabet[(triple >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

void writeDashboard(const std::filesystem::path& directory, const std::filesystem::path& page,
                    const std::string& planes_json, const std::string& blocks_binary,
                    const std::string& voxels_binary) {
  const std::string page_bytes = readWholeFile(page);
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw Error(directory.string() + ": cannot create the directory: " + error.message());
  // Data first, page last: a page never appears beside data it cannot show.
  writeWholeFile(directory / "planes.json", planes_json);
  writeWholeFile(directory / "planes.js", "window.MLMAP_PLANES = " + planes_json + ";\n");
  writeWholeFile(directory / "blocks.bin", blocks_binary);
  writeWholeFile(directory / "blocks.js", "window.MLMAP_BLOCKS = \"" + base64(blocks_binary) + "\";\n");
  if (!voxels_binary.empty()) {
    writeWholeFile(directory / "voxels.bin", voxels_binary);
    writeWholeFile(directory / "voxels.js", "window.MLMAP_VOXELS = \"" + base64(voxels_binary) + "\";\n");
  } else {
    for (const char* stale : {"voxels.js", "voxels.bin"}) {
      std::filesystem::remove(directory / stale, error);
      if (error) throw Error((directory / stale).string() + ": cannot remove an earlier export's voxels: " + error.message());
    }
  }
  writeWholeFile(directory / "index.html", page_bytes);
}

}  // namespace mlmap::io
