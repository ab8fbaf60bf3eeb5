// A patch's outline: the outer boundary of its raster cells on its plane, traced from
// the runs of touching cells the patch split hands over (outline_runs.hpp).
#include <algorithm>
#include <cstdint>
#include <optional>

#include "outline_runs.hpp"
#include "raster_frame.hpp"

namespace mlmap {
namespace {

// The cells on a dense raster over the runs' bounding box with a margin of one empty
// cell (planes in a building are compact, and lookups in an array beat a hash map by
// far): a byte per cell, column by column like the runs, so passes over it stream. A
// ceiling at 2 cm is a quarter of a million cells, so nothing else is kept per cell.
struct CellRaster {
  // Bits 0–1: the state; bits 2–5: which of an occupied cell's sides a loop has used.
  enum : std::uint8_t { kEmpty, kOccupied, kOutside };
  std::int32_t min_u = 0;
  std::int32_t min_v = 0;
  std::int64_t columns = 0;
  std::int64_t rows = 0;
  std::vector<std::uint8_t> cells;

  explicit CellRaster(const std::vector<Segment>& runs) {
    min_u = runs.front().u - 1;
    min_v = runs.front().v_low;
    std::int32_t max_v = runs.front().v_high;
    for (const Segment& run : runs) {
      min_v = std::min(min_v, run.v_low);
      max_v = std::max(max_v, run.v_high);
    }
    --min_v;
    columns = static_cast<std::int64_t>(runs.back().u) + 1 - min_u + 1;
    rows = static_cast<std::int64_t>(max_v) + 1 - min_v + 1;
    cells.assign(static_cast<std::size_t>(columns * rows), kEmpty);
    for (const Segment& run : runs) {
      std::fill_n(cells.begin() + static_cast<std::ptrdiff_t>(slot(run.u, run.v_low)), run.v_high - run.v_low + 1,
                  kOccupied);
    }
    closeOneCellGaps();
    markOutside();
  }

  std::size_t slot(std::int64_t u, std::int64_t v) const { return static_cast<std::size_t>((u - min_u) * rows + (v - min_v)); }
  std::uint8_t state(std::int64_t u, std::int64_t v) const { return cells[slot(u, v)] & 3U; }

  // The patch split joins cells a one-cell gap apart into one patch (gap_cells 2), so
  // its outline spans them too: an empty cell between two occupied ones (side by side,
  // one above the other, or diagonally opposite with none beside it) is filled; wider
  // gaps, notches, inner corners and cells touching at a corner stay as they are.
  // Without it a wall 41° to the grid (PCL's room_scan2: its raster columns alternate
  // with empty ones where cells step along the wall) or one seen in vertical scan lines
  // was outlined by its largest run of touching columns: 1.0 m² round a wall of 11.2 m²,
  // 0.55 m tall round one of 3 m, which then was no wall (classify.cpp reads heights from
  // the outline). Every filled cell lies between two occupied ones, so the margin stays
  // empty.
  void closeOneCellGaps() {
    const auto column = static_cast<std::ptrdiff_t>(rows);
    const std::vector<std::uint8_t> occupied = cells;
    auto at = [&](std::size_t k, std::ptrdiff_t offset) {
      return occupied[static_cast<std::size_t>(static_cast<std::ptrdiff_t>(k) + offset)] == kOccupied;
    };
    // Inside the margin only: every neighbour of those cells lies in the raster.
    for (std::int64_t u = 1; u + 1 < columns; ++u) {
      for (std::int64_t v = 1; v + 1 < rows; ++v) {
        const std::size_t k = slot(min_u + u, min_v + v);
        if (occupied[k] == kOccupied) continue;
        const bool across = (at(k, -1) && at(k, 1)) || (at(k, -column) && at(k, column));
        // Diagonally only where no side touches a cell: else it is an L's inner corner.
        const bool alone = !at(k, -1) && !at(k, 1) && !at(k, -column) && !at(k, column);
        const bool diagonal = (at(k, -column - 1) && at(k, column + 1)) || (at(k, -column + 1) && at(k, column - 1));
        if (across || (alone && diagonal)) cells[k] = kOccupied;
      }
    }
  }

  // The empty cells the margin reaches through empty cells side by side (all of the
  // margin, from its first cell). Only the sides facing them are traced: a loop keeps
  // one empty region on its right all the way round (where cells touch at a corner it
  // turns into the other cell's boundary, not across to the other region), so sides
  // facing a hole only make loops round holes, clockwise, or round islands inside
  // holes, smaller than the loop round the hole: neither is ever the outer boundary,
  // and a ceiling at 2 cm has tens of thousands of holes.
  void markOutside() {
    const auto column_length = static_cast<std::size_t>(rows);
    std::vector<std::size_t> stack{0};
    cells[0] = kOutside;
    auto reach = [&](std::size_t next) {
      if (cells[next] == kEmpty) {
        cells[next] = kOutside;
        stack.push_back(next);
      }
    };
    while (!stack.empty()) {
      const std::size_t current = stack.back();
      stack.pop_back();
      if (current % column_length != 0) reach(current - 1);
      if (current % column_length != column_length - 1) reach(current + 1);
      if (current >= column_length) reach(current - column_length);
      if (current + column_length < cells.size()) reach(current + column_length);
    }
  }
};

bool before(const Eigen::Vector2i& a, const Eigen::Vector2i& b) {
  return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
}

// A side of a cell, as an edge of the boundary: counter-clockwise round the cell (its
// inside on the left), 0 the bottom (v low) to 3 the left (u low).
struct Side {
  std::int32_t u;
  std::int32_t v;
  int side;

  Eigen::Vector2i from() const {
    static constexpr int kDu[4] = {0, 1, 1, 0};
    static constexpr int kDv[4] = {0, 0, 1, 1};
    return {u + kDu[side], v + kDv[side]};
  }
  Eigen::Vector2i direction() const {
    static constexpr int kDu[4] = {1, 0, -1, 0};
    static constexpr int kDv[4] = {0, 1, 0, -1};
    return {kDu[side], kDv[side]};
  }
  Eigen::Vector2i to() const { return from() + direction(); }
  // The cell across it.
  Eigen::Vector2i across() const { return Eigen::Vector2i(u, v) + Eigen::Vector2i(direction().y(), -direction().x()); }
};

// The outer boundary of the runs' cells: the sides facing the outside, chained into
// counter-clockwise loops; the loop enclosing the most area, corners only, from its
// lowest corner (smallest u, then v). The sides leaving a vertex follow from the four
// cells round it, so no side is stored: each cell's byte keeps which of its sides a
// loop has used.
std::vector<Eigen::Vector2i> outerBoundary(const std::vector<Segment>& runs) {
  CellRaster raster(runs);
  auto used = [&](const Side& side) -> bool {
    return (raster.cells[raster.slot(side.u, side.v)] >> (2 + side.side) & 1U) != 0;
  };
  auto use = [&](const Side& side) {
    raster.cells[raster.slot(side.u, side.v)] |= static_cast<std::uint8_t>(1U << (2 + side.side));
  };
  auto onBoundary = [&](const Side& side) {
    const Eigen::Vector2i other = side.across();
    return raster.state(side.u, side.v) == CellRaster::kOccupied &&
           raster.state(other.x(), other.y()) == CellRaster::kOutside;
  };
  std::vector<Eigen::Vector2i> best;
  long best_area = 0;
  auto lowest = [](const std::vector<Eigen::Vector2i>& loop) { return *std::min_element(loop.begin(), loop.end(), before); };
  std::vector<Eigen::Vector2i> loop;
  auto trace = [&](Side start) {
    loop.clear();
    std::optional<Side> edge = start;
    while (edge && !used(*edge)) {
      use(*edge);
      loop.push_back(edge->from());
      const Eigen::Vector2i in = edge->direction();
      const Eigen::Vector2i at = edge->to();
      // The sides that may leave the vertex: the bottom of the cell above-right of it,
      // the right of the one above-left, the top of the one below-left, the left of
      // the one below-right.
      const Side leaving[4] = {{at.x(), at.y(), 0}, {at.x() - 1, at.y(), 1}, {at.x() - 1, at.y() - 1, 2}, {at.x(), at.y() - 1, 3}};
      edge.reset();
      for (const Side& candidate : leaving) {
        if (!onBoundary(candidate) || used(candidate)) continue;
        // Where two cells touch at a corner only, both their sides leave the vertex:
        // turn right, into the other cell's boundary, so the loop goes round both.
        const Eigen::Vector2i out = candidate.direction();
        if (!edge || in.x() * out.y() - in.y() * out.x() < 0) edge = candidate;
      }
    }
    long twice_area = 0;
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const auto& a = loop[k];
      const auto& b = loop[(k + 1) % loop.size()];
      twice_area += static_cast<long>(a.x()) * b.y() - static_cast<long>(b.x()) * a.y();
    }
    // Of loops of equal area, the one with the lowest corner: not the one found first.
    if (twice_area > best_area || (twice_area == best_area && twice_area > 0 && before(lowest(loop), lowest(best)))) {
      best_area = twice_area;
      best = loop;
    }
  };
  for (const Segment& run : runs) {
    for (std::int32_t v = run.v_low; v <= run.v_high; ++v) {
      for (int side = 0; side < 4; ++side) {
        const Side candidate{run.u, v, side};
        if (onBoundary(candidate) && !used(candidate)) trace(candidate);
      }
    }
  }
  std::vector<Eigen::Vector2i> corners;
  for (std::size_t k = 0; k < best.size(); ++k) {
    const Eigen::Vector2i& previous = best[(k + best.size() - 1) % best.size()];
    const Eigen::Vector2i& next = best[(k + 1) % best.size()];
    const Eigen::Vector2i a = best[k] - previous;
    const Eigen::Vector2i b = next - best[k];
    if (a.x() * b.y() - a.y() * b.x() != 0) corners.push_back(best[k]);
  }
  std::rotate(corners.begin(), std::min_element(corners.begin(), corners.end(), before), corners.end());
  return corners;
}

}  // namespace

std::vector<Eigen::Vector3d> outlineOfRuns(const std::vector<Segment>& runs, double cell_size,
                                           const Eigen::Vector3d& normal, const Eigen::Vector3d& point) {
  std::vector<Eigen::Vector3d> outline;
  if (runs.empty()) return outline;
  const RasterFrame frame(normal, point, cell_size);
  for (const Eigen::Vector2i& corner : outerBoundary(runs)) outline.push_back(frame.corner(corner.x(), corner.y()));
  // From the same first corner, the other way round.
  if (!frame.keepsTurn()) std::reverse(outline.begin() + 1, outline.end());
  return outline;
}

std::vector<Eigen::Vector3d> cornersOfRuns(const std::vector<Segment>& runs, double cell_size,
                                           const Eigen::Vector3d& normal, const Eigen::Vector3d& point) {
  const RasterFrame frame(normal, point, cell_size);
  std::vector<Eigen::Vector3d> corners;
  corners.reserve(4 * runs.size());
  for (const Segment& run : runs) {
    for (const std::int32_t u : {run.u, run.u + 1}) {
      corners.push_back(frame.corner(u, run.v_low));
      corners.push_back(frame.corner(u, run.v_high + 1));
    }
  }
  return corners;
}

}  // namespace mlmap
