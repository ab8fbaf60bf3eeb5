#include "unseen_gaps.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace mlmap {
namespace {

// A gap nothing was seen beside is bridged where the wall's pieces cover at least a third
// of the joined stretch: the shipped corridor's west end wall, 2.95 m unseen between pieces
// of 0.5 and 1.3 m (its first pose's blind sector, 1.5 m from it), is one; the two
// side corridors' end walls, 15.5 m apart, are two (corridors up to 3 m wide).
constexpr double kMaxUnseenPerSeen = 2.0;

struct Piece {
  std::size_t patch = 0;
  double low = 0.0;   // m, extent along the wall
  double high = 0.0;
  double level = 0.0;  // m, its blocks' mean distance from the plane
};

Piece pieceOf(const BlockGrid& grid, const std::vector<Patch>& patches, std::size_t index, const Eigen::Vector3d& normal,
              const Eigen::Vector3d& u_axis, const Eigen::Vector3d& point) {
  Piece piece{index, 1e300, -1e300, 0.0};
  for (const std::uint32_t id : patches[index].blocks) {
    const Eigen::Vector3d offset = grid.blocks()[id].point.cast<double>() - point;
    const double u = u_axis.dot(offset);
    piece.low = std::min(piece.low, u);
    piece.high = std::max(piece.high, u);
    piece.level += normal.dot(offset);
  }
  piece.level /= static_cast<double>(patches[index].blocks.size());
  return piece;
}

// Which sides of the wall the map holds blocks on between u_low and u_high, further than
// epsilon from the plane and closer than reach: both where the scanner saw through an
// opening (the near side always has the floor), neither where it never looked there.
struct SidesSeen {
  bool front = false;
  bool behind = false;
};

SidesSeen sidesSeen(const BlockGrid& grid, const Eigen::Vector3d& normal, const Eigen::Vector3d& u_axis,
                    const Eigen::Vector3d& point, double u_low, double u_high, double epsilon, double reach) {
  const double cell = grid.cellSize();
  const Eigen::Vector3d a = point + u_axis * u_low;
  const Eigen::Vector3d b = point + u_axis * u_high;
  const auto index = [cell](double coordinate) { return static_cast<std::int64_t>(std::floor(coordinate / cell)); };
  const std::int64_t j_low = index(std::min(a.x(), b.x()) - reach);
  const std::int64_t j_high = index(std::max(a.x(), b.x()) + reach);
  SidesSeen seen;
  // Row by row, to stop as soon as both sides are seen.
  for (std::int64_t i = index(std::min(a.y(), b.y()) - reach); i <= index(std::max(a.y(), b.y()) + reach); ++i) {
    grid.forEachInCells(i, i, j_low, j_high, [&](std::uint32_t id) {
      const Eigen::Vector3d offset = grid.blocks()[id].point.cast<double>() - point;
      const double u = u_axis.dot(offset);
      const double distance = normal.dot(offset);
      if (u <= u_low || u >= u_high || std::abs(distance) < epsilon || std::abs(distance) > reach) return;
      (distance > 0.0 ? seen.front : seen.behind) = true;
    });
    if (seen.front && seen.behind) break;
  }
  return seen;
}

}  // namespace

void joinUnseenGaps(const BlockGrid& grid, std::vector<Patch>& patches, const Eigen::Vector3d& normal,
                    const Eigen::Vector3d& point, double epsilon, std::size_t min_blocks, double min_surface,
                    double reach, double max_step) {
  if (patches.size() < 2 || std::abs(normal.z()) >= 0.2) return;
  Eigen::Vector3d u_axis;
  Eigen::Vector3d v_axis;
  planeBasis(normal, u_axis, v_axis);
  std::vector<Piece> pieces;
  for (std::size_t k = 0; k < patches.size(); ++k) {
    if (patches[k].blocks.size() >= min_blocks && patches[k].surface >= min_surface) {
      pieces.push_back(pieceOf(grid, patches, k, normal, u_axis, point));
    }
  }
  if (pieces.size() < 2) return;
  // Layers first: pieces sorted by level, a new layer where consecutive levels differ by
  // more than max_step; the pieces of each layer are joined on their own.
  std::stable_sort(pieces.begin(), pieces.end(), [](const Piece& a, const Piece& b) { return a.level < b.level; });
  bool joined_any = false;
  std::size_t layer_begin = 0;
  for (std::size_t end = 1; end <= pieces.size(); ++end) {
    if (end < pieces.size() && pieces[end].level - pieces[end - 1].level <= max_step) continue;
    std::vector<Piece> layer(pieces.begin() + static_cast<long>(layer_begin), pieces.begin() + static_cast<long>(end));
    layer_begin = end;
    if (layer.size() < 2) continue;
    std::stable_sort(layer.begin(), layer.end(), [](const Piece& a, const Piece& b) { return a.low < b.low; });
    // Along the wall, each piece joins the run before it when a gap of more than a cell
    // separates them and nothing was seen through it. Pieces beside each other along
    // the wall (one above the other) stay apart: their gap is not along the wall.
    // A gap beside which nothing at all was seen, on either side of the wall, is bridged
    // only where the wall's pieces (the run's and the next one, a cell a column) cover at
    // least a third of the joined stretch: coplanar walls of rooms apart (issue 19: two
    // side corridors' end walls 15.5 m apart, the rooms between them never entered) have
    // nothing beside a long gap. Where something was seen beside it (the floor up to the
    // wall, a cabinet in front), the scanner looked that way and the wall was hidden or
    // missed, at any length.
    const double cell = grid.cellSize();
    const auto seenLength = [cell](const Piece& piece) { return piece.high - piece.low + cell; };
    std::size_t run = layer.front().patch;
    double run_high = layer.front().high;
    double run_seen = seenLength(layer.front());
    for (std::size_t n = 1; n < layer.size(); ++n) {
      const Piece& piece = layer[n];
      const double missing = piece.low - run_high - cell;
      const SidesSeen seen =
          missing > 0.0 ? sidesSeen(grid, normal, u_axis, point, run_high, piece.low, epsilon, reach) : SidesSeen{};
      // Beside the gap's inside: the floor of a room ending at the wall's last column
      // is no evidence.
      const auto besideGap = [&] {
        const SidesSeen inside =
            sidesSeen(grid, normal, u_axis, point, run_high + cell, piece.low - cell, epsilon, reach);
        return inside.front || inside.behind;
      };
      const bool joins = missing > 0.0 && !(seen.front && seen.behind) &&
                         (missing <= kMaxUnseenPerSeen * (run_seen + seenLength(piece)) || besideGap());
      if (joins) {
        Patch& into = patches[run];
        Patch& from = patches[piece.patch];
        std::vector<std::uint32_t> blocks;
        blocks.reserve(into.blocks.size() + from.blocks.size());
        std::merge(into.blocks.begin(), into.blocks.end(), from.blocks.begin(), from.blocks.end(),
                   std::back_inserter(blocks));
        into.blocks = std::move(blocks);
        into.surface += from.surface;
        from = Patch{};
        run_high = std::max(run_high, piece.high);
        run_seen += seenLength(piece);
        joined_any = true;
        continue;
      }
      run = piece.patch;
      run_high = piece.high;
      run_seen = seenLength(piece);
    }
  }
  if (!joined_any) return;
  std::erase_if(patches, [](const Patch& patch) { return patch.blocks.empty(); });
  std::stable_sort(patches.begin(), patches.end(), [](const Patch& a, const Patch& b) { return a.surface > b.surface; });
}

}  // namespace mlmap
