#include "level_cover.hpp"

#include <algorithm>
#include <limits>

namespace mlmap {
namespace {

// Sets line[k] where any of the marks at k − reach .. k + reach is set, in place along
// `count` entries `stride` apart (a row or a column of a box).
void dilateLine(std::uint8_t* line, std::int64_t count, std::int64_t stride, std::int64_t reach,
                std::vector<std::int64_t>& prefix) {
  prefix.assign(static_cast<std::size_t>(count + 1), 0);
  for (std::int64_t k = 0; k < count; ++k)
    prefix[static_cast<std::size_t>(k + 1)] = prefix[static_cast<std::size_t>(k)] + (line[k * stride] != 0 ? 1 : 0);
  for (std::int64_t k = 0; k < count; ++k) {
    const std::int64_t from = std::max<std::int64_t>(0, k - reach);
    const std::int64_t to = std::min<std::int64_t>(count, k + reach + 1);
    line[k * stride] = prefix[static_cast<std::size_t>(to)] > prefix[static_cast<std::size_t>(from)] ? 1 : 0;
  }
}

}  // namespace

LevelCover::LevelCover(const MLMap& map, const std::function<std::uint32_t(std::int32_t)>& slot_of,
                       const std::vector<bool>& level, std::int32_t reach) {
  // Each level slot's box of cells holding its blocks.
  constexpr std::int64_t kNone = std::numeric_limits<std::int64_t>::max();
  struct Box {
    std::int64_t i_min = kNone, j_min = kNone, i_max = -kNone, j_max = -kNone;
  };
  std::vector<Box> boxes(level.size());
  std::vector<std::pair<CellIndex, std::uint32_t>> marks;  // (cell, slot) of every level block
  for (std::size_t n = 0; n < map.cellCount(); ++n) {
    const CellIndex cell = map.cellAt(n);
    for (const Block& block : map.blocksAt(n)) {
      if (block.plane <= 0) continue;
      const std::uint32_t slot = slot_of(block.plane);
      if (slot == 0 || slot >= level.size() || !level[slot]) continue;
      Box& box = boxes[slot];
      box.i_min = std::min<std::int64_t>(box.i_min, cell.i);
      box.i_max = std::max<std::int64_t>(box.i_max, cell.i);
      box.j_min = std::min<std::int64_t>(box.j_min, cell.j);
      box.j_max = std::max<std::int64_t>(box.j_max, cell.j);
      marks.emplace_back(cell, slot);
    }
  }
  std::vector<std::int64_t> cover_of(level.size(), -1);
  for (std::uint32_t slot = 0; slot < boxes.size(); ++slot) {
    const Box& box = boxes[slot];
    if (box.i_min == kNone) continue;
    Cover cover;
    cover.slot = slot;
    cover.i0 = box.i_min - reach;
    cover.j0 = box.j_min - reach;
    cover.rows = box.i_max - box.i_min + 1 + 2 * static_cast<std::int64_t>(reach);
    cover.columns = box.j_max - box.j_min + 1 + 2 * static_cast<std::int64_t>(reach);
    cover.bits.assign(static_cast<std::size_t>(cover.rows * cover.columns), 0);
    cover_of[slot] = static_cast<std::int64_t>(covers_.size());
    covers_.push_back(std::move(cover));
  }
  for (const auto& [cell, slot] : marks) {
    Cover& cover = covers_[static_cast<std::size_t>(cover_of[slot])];
    cover.bits[static_cast<std::size_t>((cell.i - cover.i0) * cover.columns + (cell.j - cover.j0))] = 1;
  }
  // A square of 2·reach + 1 cells round each block: along the rows, then the columns.
  std::vector<std::int64_t> prefix;
  for (Cover& cover : covers_) {
    for (std::int64_t i = 0; i < cover.rows; ++i)
      dilateLine(cover.bits.data() + i * cover.columns, cover.columns, 1, reach, prefix);
    for (std::int64_t j = 0; j < cover.columns; ++j)
      dilateLine(cover.bits.data() + j, cover.rows, cover.columns, reach, prefix);
  }
}

}  // namespace mlmap
