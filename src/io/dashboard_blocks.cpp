#include "mlmap/io/dashboard_blocks.hpp"

#include <cmath>
#include <cstring>

#include "file_bytes.hpp"
#include "mlmap/error.hpp"

namespace mlmap::io {
namespace {

constexpr char kMagic[8] = {'M', 'L', 'B', 'L', 'O', 'C', 'K', 'S'};
constexpr std::size_t kHeaderBytes = 24;
constexpr std::size_t kBytesPerBlock = 4 + 4 + 4 + 4 + 4 + 1;

}  // namespace

std::string dashboardBlocks(const MLMap& map) {
  const std::size_t count = map.blockCount();
  std::string bytes(kHeaderBytes + kBytesPerBlock * count, '\0');
  std::memcpy(bytes.data(), kMagic, sizeof(kMagic));
  storeLittleEndian<std::uint32_t>(bytes.data() + 8, kDashboardBlocksVersion);
  storeLittleEndian<std::uint32_t>(bytes.data() + 12, static_cast<std::uint32_t>(count));
  storeLittleEndian<double>(bytes.data() + 16, map.cellSize());
  char* const column_j = bytes.data() + kHeaderBytes;
  char* const column_i = column_j + 4 * count;
  char* const column_top = column_i + 4 * count;
  char* const column_depth = column_top + 4 * count;
  char* const column_plane = column_depth + 4 * count;
  char* const column_kind = column_plane + 4 * count;
  std::size_t k = 0;
  for (std::size_t n = 0; n < map.cellCount(); ++n) {
    const CellIndex cell = map.cellAt(n);
    for (const Block& block : map.blocksAt(n)) {
      storeLittleEndian<std::int32_t>(column_j + 4 * k, cell.j);
      storeLittleEndian<std::int32_t>(column_i + 4 * k, cell.i);
      storeLittleEndian<float>(column_top + 4 * k, block.height);
      storeLittleEndian<float>(column_depth + 4 * k, block.depth);
      storeLittleEndian<std::int32_t>(column_plane + 4 * k, block.plane);
      column_kind[k] = static_cast<char>(block.kind);
      ++k;
    }
  }
  if (k != count) throw Error("dashboard blocks: the map counts " + std::to_string(count) + " blocks but holds " + std::to_string(k));
  return bytes;
}

DashboardBlocks parseDashboardBlocks(std::string_view bytes, const std::string& name) {
  const auto fail = [&name](const std::string& what) -> Error { return Error(name + ": " + what); };
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    throw fail("not an mlmap blocks file (no \"MLBLOCKS\" header)");
  }
  const auto version = loadLittleEndian<std::uint32_t>(bytes.data() + 8);
  if (version != kDashboardBlocksVersion) {
    throw fail("blocks file version " + std::to_string(version) + ", this reader knows version " +
               std::to_string(kDashboardBlocksVersion));
  }
  const std::size_t count = loadLittleEndian<std::uint32_t>(bytes.data() + 12);
  // Compared as a count, not as bytes: 21·N cannot overflow a size_t from a uint32.
  if ((bytes.size() - kHeaderBytes) % kBytesPerBlock != 0 || (bytes.size() - kHeaderBytes) / kBytesPerBlock != count) {
    throw fail("the header says " + std::to_string(count) + " blocks, which take " +
               std::to_string(kHeaderBytes + kBytesPerBlock * count) + " bytes, but the file has " +
               std::to_string(bytes.size()) + " (cut short or damaged?)");
  }
  DashboardBlocks result;
  result.cell_size = loadLittleEndian<double>(bytes.data() + 16);
  if (!std::isfinite(result.cell_size) || result.cell_size <= 0.0) throw fail("the cell size is not a positive number");
  const char* const column_j = bytes.data() + kHeaderBytes;
  const char* const column_i = column_j + 4 * count;
  const char* const column_top = column_i + 4 * count;
  const char* const column_depth = column_top + 4 * count;
  const char* const column_plane = column_depth + 4 * count;
  const char* const column_kind = column_plane + 4 * count;
  result.blocks.resize(count);
  for (std::size_t k = 0; k < count; ++k) {
    DashboardBlock& block = result.blocks[k];
    block.cell = {loadLittleEndian<std::int32_t>(column_i + 4 * k), loadLittleEndian<std::int32_t>(column_j + 4 * k)};
    block.top = loadLittleEndian<float>(column_top + 4 * k);
    block.depth = loadLittleEndian<float>(column_depth + 4 * k);
    block.plane = loadLittleEndian<std::int32_t>(column_plane + 4 * k);
    const auto kind = static_cast<unsigned char>(column_kind[k]);
    const auto where = [k] { return "block " + std::to_string(k); };
    if (!std::isfinite(block.top)) throw fail(where() + ": the top is not a finite number");
    if (!std::isfinite(block.depth) || block.depth < 0.0F) throw fail(where() + ": the depth is not a number ≥ 0");
    if (kind > 1) throw fail(where() + ": kind " + std::to_string(kind) + ", expected 0 (horizontal) or 1 (vertical)");
    block.kind = static_cast<BlockKind>(kind);
  }
  return result;
}

}  // namespace mlmap::io
