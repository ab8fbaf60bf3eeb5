#include "mlmap/planes/block_grid.hpp"

#include <algorithm>
#include <limits>

#include "mlmap/error.hpp"

namespace mlmap {

BlockGrid::BlockGrid(const MLMap& map) : cell_size_(map.cellSize()) {
  const std::size_t cell_count = map.cellCount();
  blocks_.reserve(map.blockCount());
  cell_first_.reserve(cell_count + 1);
  min_i_ = std::numeric_limits<std::int64_t>::max();
  min_j_ = std::numeric_limits<std::int64_t>::max();
  std::int64_t max_i = std::numeric_limits<std::int64_t>::min();
  std::int64_t max_j = std::numeric_limits<std::int64_t>::min();
  for (std::size_t n = 0; n < cell_count; ++n) {
    cell_first_.push_back(static_cast<std::uint32_t>(blocks_.size()));
    const CellIndex cell = map.cellAt(n);
    const Eigen::Vector2d centre = map.cellCenter(cell);
    for (const Block& block : map.blocksAt(n)) {
      PlaneBlock view;
      view.top = block.height;
      view.bottom = block.bottom();
      // A vertical block shallower than a cell is the edge of a horizontal surface
      // (a table top with its rim, a stair tread with the top of its riser) far more
      // often than a wall: eRMSM treats it as horizontal, at its top.
      view.vertical = block.isVertical() && block.depth >= cell_size_;
      view.surface = view.vertical ? static_cast<float>(block.depth / cell_size_) : 1.0F;
      view.point = Eigen::Vector3f(static_cast<float>(centre.x()), static_cast<float>(centre.y()),
                                   view.vertical ? 0.5F * (view.top + view.bottom) : view.top);
      view.cell = cell;
      blocks_.push_back(view);
    }
    min_i_ = std::min<std::int64_t>(min_i_, cell.i);
    min_j_ = std::min<std::int64_t>(min_j_, cell.j);
    max_i = std::max<std::int64_t>(max_i, cell.i);
    max_j = std::max<std::int64_t>(max_j, cell.j);
  }
  cell_first_.push_back(static_cast<std::uint32_t>(blocks_.size()));
  if (cell_count == 0) return;
  rows_ = max_i - min_i_ + 1;
  columns_ = max_j - min_j_ + 1;
  // A building at a few centimetres fits easily; a map spread over kilometres does not.
  constexpr std::int64_t kMaxGridCells = std::int64_t{1} << 28;
  if (rows_ > kMaxGridCells / columns_) {
    throw Error("map too sparse for plane detection: " + std::to_string(rows_) + " × " +
                std::to_string(columns_) + " cells in its bounding box");
  }
  grid_.assign(static_cast<std::size_t>(rows_ * columns_), -1);
  for (std::size_t n = 0; n < cell_count; ++n) {
    const CellIndex cell = map.cellAt(n);
    grid_[static_cast<std::size_t>((cell.i - min_i_) * columns_ + (cell.j - min_j_))] =
        static_cast<std::int32_t>(n);
  }
}

}  // namespace mlmap
