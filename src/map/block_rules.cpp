// Where the printed text of section IV is loose we read it as follows:
// - σ is a variance; the Kalman rule is h ← (σ_m·h + σ·p_z)/(σ + σ_m),
//   σ ← σ·σ_m/(σ + σ_m).
// - "A block collects a measurement" when p_z lies within cell_size of the block's
//   extent [h − d, h]: the printed |p_z − h| < cell_size ∧ |(h − d) − p_z| < cell_size
//   cannot hold inside a vertical block deeper than two cells, yet Fig. 3 case 3 says
//   such a point changes nothing.
// - The 3σ test gates the innovation, |p_z − h| < 3·√(σ + σ_m): the block's own σ
//   shrinks like σ_m / n, and against it alone ordinary range noise turns a well
//   observed floor into shallow vertical blocks.
// - A vertical block's h and σ are those of its highest measurement; a merge (case 4)
//   keeps the highest block's σ unless the new point is above it.
#include "block_rules.hpp"

#include <algorithm>
#include <cmath>

namespace mlmap {
namespace {

// The rules of section IV for a measurement collected by exactly one block:
// Fig. 3 cases 2, 3 and 5.
void updateBlock(Block& block, double z, double variance) {
  const double height = block.height;
  if (!block.isVertical()) {
    // The 3σ test gates the innovation (see the top of this file).
    const double gate = 3.0 * std::sqrt(static_cast<double>(block.variance) + variance);
    if (std::abs(z - height) < gate) {
      const double sigma = block.variance;
      block.height = static_cast<float>((variance * height + sigma * z) / (sigma + variance));
      block.variance = static_cast<float>(sigma * variance / (sigma + variance));
      return;
    }
    block.kind = BlockKind::Vertical;
    block.depth = static_cast<float>(std::abs(z - height));
    if (z > height) {
      block.height = static_cast<float>(z);
      block.variance = static_cast<float>(variance);
    }
    return;
  }
  // Vertical: h and σ are those of the highest measurement, d spans down to the lowest.
  const double bottom = height - block.depth;
  if (z > height) {
    block.height = static_cast<float>(z);
    block.depth = static_cast<float>(z - bottom);
    block.variance = static_cast<float>(variance);
  } else if (z < bottom) {
    block.depth = static_cast<float>(height - z);
  }
}

}  // namespace

int addMeasurement(Block* blocks, int count, float top, float bottom, float variance, float reach,
                   const PointStats& points) {
  // A block collects a measurement when it lies within cell_size of the block's
  // extent [h − d, h]. Blocks are sorted and at least cell_size apart,
  // so the collectors of [bottom, top] are adjacent in the run.
  int first_hit = -1;
  int last_hit = -1;
  int insert_at = count;
  for (int k = 0; k < count; ++k) {
    const Block& block = blocks[k];
    if (top > block.bottom() - reach && bottom < block.height + reach) {
      if (first_hit < 0) first_hit = k;
      last_hit = k;
    } else if (top < block.bottom() && insert_at == count) {
      insert_at = k;
    }
  }
  const bool is_point = top == bottom;
  if (first_hit >= 0 && first_hit == last_hit && is_point) {
    updateBlock(blocks[first_hit], top, variance);
    blocks[first_hit].points.merge(points);
    return count;
  }
  if (first_hit >= 0) {
    // Fig. 3 case 4: the measurement bridges blocks (or spans more than one);
    // all of them become one vertical block.
    const Block& lowest = blocks[first_hit];
    const Block& highest = blocks[last_hit];
    Block merged;
    merged.kind = BlockKind::Vertical;
    const bool new_top = top > highest.height;
    merged.height = new_top ? top : highest.height;
    merged.variance = new_top ? variance : highest.variance;
    merged.depth = merged.height - std::min(lowest.bottom(), bottom);
    for (int k = first_hit; k <= last_hit; ++k) merged.points.merge(blocks[k].points);
    merged.points.merge(points);
    blocks[first_hit] = merged;
    const int removed = last_hit - first_hit;
    std::copy(blocks + last_hit + 1, blocks + count, blocks + first_hit + 1);
    return count - removed;
  }
  // Fig. 3 case 1: nobody collects the measurement; a new block.
  std::copy_backward(blocks + insert_at, blocks + count, blocks + count + 1);
  blocks[insert_at] = is_point ? Block{top, variance, 0.0F, 0, BlockKind::Horizontal, points}
                               : Block{top, variance, top - bottom, 0, BlockKind::Vertical, points};
  return count + 1;
}

}  // namespace mlmap
