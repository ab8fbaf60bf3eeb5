// PlaneScorer's index (plane_scorer.hpp): its bins, layers and tiles built from the
// blocks' directions and points. Their sums as blocks are taken are kept by
// plane_scorer_sums.cpp; the queries that walk it (score, matching, near) are in
// plane_scorer.cpp.
#include "plane_scorer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <type_traits>

#include "counting_sort.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap {
namespace {

constexpr int kElevationRows = 9;  // 10° each over [0°, 90°]; the top row is one polar cap
// A tile is this many cells wide: large enough that a plane's slab holds whole tiles,
// small enough that the slab's faces cut few blocks.
constexpr int kTileCells = 16;
// A layer node holds at least this many blocks: in a building's clutter most slices
// hold a block or two, and a node per slice cost more to test than its blocks.
constexpr std::size_t kMinLayerBlocks = 64;
// Maps of fewer blocks build their index on one thread (plane_scorer_sums.cpp: its
// refreshes and takes).
constexpr std::size_t kParallelBlocks = 100000;

// Azimuth columns per elevation row, so that bins cover similar solid angles; and the
// first bin of every row.
struct BinLayout {
  std::array<int, kElevationRows> columns{};
  std::array<int, kElevationRows + 1> first{};
  BinLayout() {
    for (int row = 0; row < kElevationRows; ++row) {
      const double elevation = (row + 0.5) * (std::numbers::pi / 2) / kElevationRows;
      columns[static_cast<std::size_t>(row)] =
          row == kElevationRows - 1 ? 1 : std::max(1, static_cast<int>(std::lround(36.0 * std::cos(elevation))));
      first[static_cast<std::size_t>(row) + 1] = first[static_cast<std::size_t>(row)] + columns[static_cast<std::size_t>(row)];
    }
  }
};

const BinLayout& binLayout() {
  static const BinLayout layout;
  return layout;
}

int binCount() { return binLayout().first[kElevationRows]; }

// The sine of a cone's radius from its cosine, as the cone test once computed it per query.
float sineOf(float cos_r) { return std::sqrt(std::max(0.0F, 1.0F - cos_r * cos_r)); }

// Above this |z| a direction's elevation is surely in the top row (80° and up: sin 80°
// = 0.98481), which is one bin whatever the azimuth: floors and ceilings, most blocks
// of a building, skip the trigonometry and land where it would put them.
constexpr float kSurelyPolar = 0.9849F;

int binOf(const Eigen::Vector3f& direction) {
  // Unsigned axes: use the upper hemisphere's representative.
  const Eigen::Vector3f axis = direction.z() < 0.0F ? Eigen::Vector3f(-direction) : direction;
  if (axis.z() >= kSurelyPolar) return binLayout().first[kElevationRows - 1];
  const double elevation = std::asin(std::min(1.0F, axis.z()));
  double azimuth = std::atan2(axis.y(), axis.x());
  if (azimuth < 0.0) azimuth += 2.0 * std::numbers::pi;
  const int row = std::min(kElevationRows - 1, static_cast<int>(elevation / (std::numbers::pi / 2) * kElevationRows));
  const int columns = binLayout().columns[static_cast<std::size_t>(row)];
  const int column = std::min(columns - 1, static_cast<int>(azimuth / (2 * std::numbers::pi) * columns));
  return binLayout().first[static_cast<std::size_t>(row)] + column;
}

}  // namespace

PlaneScorer::PlaneScorer(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                         double epsilon, double kappa_rad, int threads)
    : grid_(grid),
      directions_(directions),
      epsilon_(static_cast<float>(epsilon)),
      cos_kappa_(static_cast<float>(std::cos(kappa_rad))),
      taken_(grid.size(), 0),
      position_(grid.size(), UINT32_MAX) {
  const auto bins = static_cast<std::size_t>(binCount());
  // Each bin's axis: the mean of its members' directions (so a bin of wall blocks,
  // whose directions are level, has a level axis), and a frame across it.
  FillVector<std::int32_t> bin_of(grid.size());
  const auto count = static_cast<std::int64_t>(grid.size());
#ifdef _OPENMP
  // Small maps build their index on one thread: there a parallel region saves little,
  // and on a shared machine it can wait milliseconds for a core.
  team_ = grid.size() < kParallelBlocks ? 1 : threads > 0 ? threads : omp_get_max_threads();
#else
  team_ = std::max(1, threads);  // the pragmas are ignored
#endif
  const int team = team_;
#pragma omp parallel for schedule(static) num_threads(team) if (team > 1)
  for (std::int64_t id = 0; id < count; ++id) {
    const Eigen::Vector3f& d = directions[static_cast<std::size_t>(id)];
    bin_of[static_cast<std::size_t>(id)] = d.squaredNorm() > 0.0F ? binOf(d) : -1;
  }
  std::vector<Eigen::Vector3f> sums(bins, Eigen::Vector3f::Zero());
  std::vector<Eigen::Vector3f> first(bins, Eigen::Vector3f::Zero());
  std::vector<std::uint32_t> directed;  // ids with a direction, ascending
  directed.reserve(grid.size());
  for (std::uint32_t id = 0; id < grid.size(); ++id) {
    const int bin = bin_of[id];
    if (bin < 0) {
      undirected_.push_back(id);
      undirected_points_.push_back(grid.blocks()[id].point);
      continue;
    }
    directed.push_back(id);
    const Eigen::Vector3f& d = directions[id];
    Eigen::Vector3f& reference = first[static_cast<std::size_t>(bin)];
    if (reference.squaredNorm() == 0.0F) reference = d;
    sums[static_cast<std::size_t>(bin)] += d.dot(reference) < 0.0F ? Eigen::Vector3f(-d) : d;
  }
  frames_.resize(bins);
  for (std::size_t b = 0; b < bins; ++b) {
    Frame& frame = frames_[b];
    frame.a = sums[b].squaredNorm() > 0.0F ? sums[b].normalized() : Eigen::Vector3f::UnitZ();
    const Eigen::Vector3f helper = std::abs(frame.a.z()) < 0.9F ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
    frame.u = frame.a.cross(helper).normalized();
    frame.v = frame.a.cross(frame.u);
  }
  const double layer_size = 0.5 * epsilon;
  const double tile_size = kTileCells * grid.cellSize();
  // Each block's place in the index: its bin, its layer in the bin, its tile in the layer.
  struct Place {
    std::int32_t bin, layer, tile_u, tile_v;
    std::uint32_t id;
  };
  // Each block on its own, so on all threads.
  FillVector<Place> order(directed.size());
  const auto directed_count = static_cast<std::int64_t>(directed.size());
#pragma omp parallel for schedule(static) num_threads(team) if (team > 1)
  for (std::int64_t n = 0; n < directed_count; ++n) {
    const std::uint32_t id = directed[static_cast<std::size_t>(n)];
    const Frame& frame = frames_[static_cast<std::size_t>(bin_of[id])];
    const Eigen::Vector3f& p = grid.blocks()[id].point;
    order[static_cast<std::size_t>(n)] = {bin_of[id], static_cast<std::int32_t>(std::floor(frame.a.dot(p) / layer_size)),
                                          static_cast<std::int32_t>(std::floor(frame.u.dot(p) / tile_size)),
                                          static_cast<std::int32_t>(std::floor(frame.v.dot(p) / tile_size)), id};
  }
  // Ordered by (bin, layer, tile), ids ascending within a tile: stable sorts from the
  // least significant key (a comparison sort of the 5-tuples cost far more), two of
  // them: by the tile's number in the box of all tiles, then by the layer's number
  // among all bins' layers (each bin's layers follow the previous bin's).
  constexpr std::int32_t kHighest = std::numeric_limits<std::int32_t>::max();
  constexpr std::int32_t kLowest = std::numeric_limits<std::int32_t>::min();
  std::int32_t low_u = kHighest, high_u = kLowest, low_v = kHighest, high_v = kLowest;
  std::vector<std::int32_t> low_layer(bins, kHighest);
  std::vector<std::int32_t> high_layer(bins, kLowest);
  std::int32_t* low_layers = low_layer.data();
  std::int32_t* high_layers = high_layer.data();
#pragma omp parallel for schedule(static) num_threads(team) if (team > 1) \
    reduction(min : low_u, low_v, low_layers[:bins]) reduction(max : high_u, high_v, high_layers[:bins])
  for (std::int64_t n = 0; n < directed_count; ++n) {
    const Place& place = order[static_cast<std::size_t>(n)];
    low_u = std::min(low_u, place.tile_u);
    high_u = std::max(high_u, place.tile_u);
    low_v = std::min(low_v, place.tile_v);
    high_v = std::max(high_v, place.tile_v);
    const auto bin = static_cast<std::size_t>(place.bin);
    low_layers[bin] = std::min(low_layers[bin], place.layer);
    high_layers[bin] = std::max(high_layers[bin], place.layer);
  }
  if (order.empty()) low_u = high_u = low_v = high_v = 0;
  const std::int64_t tile_rows = static_cast<std::int64_t>(high_v) - low_v + 1;
  std::vector<std::int64_t> first_layer(bins + 1, 0);
  for (std::size_t b = 0; b < bins; ++b) {
    const bool used = low_layer[b] <= high_layer[b];
    first_layer[b + 1] = first_layer[b] + (used ? static_cast<std::int64_t>(high_layer[b]) - low_layer[b] + 1 : 0);
  }
  stableSortBy(
      order,
      [&](const Place& place) {
        return (static_cast<std::int64_t>(place.tile_u) - low_u) * tile_rows + (static_cast<std::int64_t>(place.tile_v) - low_v);
      },
      team);
  stableSortBy(
      order,
      [&](const Place& place) {
        const auto bin = static_cast<std::size_t>(place.bin);
        return first_layer[bin] + (static_cast<std::int64_t>(place.layer) - low_layer[bin]);
      },
      team);
  bins_.resize(bins);
  // Reserved whole: a tile per change of slice or tile, a layer per slice at most.
  std::size_t slice_count = 0;
  std::size_t tile_count = 0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const bool new_slice = k == 0 || order[k - 1].bin != order[k].bin || order[k - 1].layer != order[k].layer;
    slice_count += new_slice ? 1 : 0;
    tile_count += new_slice || order[k - 1].tile_u != order[k].tile_u || order[k - 1].tile_v != order[k].tile_v ? 1 : 0;
  }
  layers_.reserve(slice_count);
  bin_of_layer_.reserve(slice_count);
  tiles_.reserve(tile_count);
  layer_of_tile_.reserve(tile_count);
  tile_of_.reserve(order.size());
  std::size_t layer_first = 0;  // the current layer's first block
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Place& place = order[k];
    const Place* previous = k == 0 ? nullptr : &order[k - 1];
    const auto bin = place.bin;
    const bool new_bin = previous == nullptr || previous->bin != bin;
    const bool next_slice = !new_bin && previous->layer != place.layer;
    const bool new_layer = new_bin || (next_slice && k - layer_first >= kMinLayerBlocks);
    const bool new_tile = new_layer || next_slice || previous->tile_u != place.tile_u || previous->tile_v != place.tile_v;
    if (new_layer) layer_first = k;
    if (new_bin) bins_[static_cast<std::size_t>(bin)].begin = static_cast<std::uint32_t>(layers_.size());
    if (new_layer) {
      layers_.emplace_back();
      layers_.back().begin = static_cast<std::uint32_t>(tiles_.size());
      bin_of_layer_.push_back(static_cast<std::uint32_t>(bin));
    }
    if (new_tile) {
      tiles_.emplace_back();
      tiles_.back().begin = static_cast<std::uint32_t>(k);
      layer_of_tile_.push_back(static_cast<std::uint32_t>(layers_.size() - 1));
    }
    bins_[static_cast<std::size_t>(bin)].end = static_cast<std::uint32_t>(layers_.size());
    layers_.back().end = static_cast<std::uint32_t>(tiles_.size());
    tile_of_.push_back(static_cast<std::uint32_t>(tiles_.size() - 1));
    tiles_.back().end = static_cast<std::uint32_t>(k + 1);
  }
  // Each block's place on its own: on all threads (the writes land all over position_).
#pragma omp parallel for schedule(static) num_threads(team) if (team > 1)
  for (std::int64_t k = 0; k < directed_count; ++k) {
    position_[order[static_cast<std::size_t>(k)].id] = static_cast<std::uint32_t>(k);
  }
  // The order's memory goes first, for the arrays to reuse: fresh pages cost a fault
  // each (a 4 KB page in ~1.7 µs here), reused ones nothing.
  const std::size_t indexed = order.size();
  FillVector<Place>().swap(order);
  FillVector<std::int32_t>().swap(bin_of);
  std::vector<std::uint32_t>().swap(directed);
  // The blocks' data in index order, on all threads: scattered from a pass over the
  // grid in id order, which reads each block once and whole (a gather in index order
  // read a block's cache lines twice over, once for the floor, once for the ceiling
  // sharing its cells, and the blocks are far larger than what is kept of them).
  ids_.resize(indexed);
  points_.resize(indexed);
  block_directions_.resize(indexed);
  surfaces_.resize(indexed);
  half_depths_.resize(indexed);
  order_taken_.assign(indexed, 0);
#pragma omp parallel for schedule(static) num_threads(team) if (team > 1)
  for (std::int64_t signed_id = 0; signed_id < count; ++signed_id) {
    const auto id = static_cast<std::uint32_t>(signed_id);
    const std::uint32_t n = position_[id];
    if (n == UINT32_MAX) continue;
    const PlaneBlock& block = grid.blocks()[id];
    ids_[n] = id;
    points_[n] = block.point;
    block_directions_[n] = directions[id];
    surfaces_[n] = block.surface;
    half_depths_[n] = block.vertical ? 0.5F * (block.top - block.bottom) : 0.0F;
  }
  // Every node's cone and box: a tile's from its blocks (on all threads, its sums after
  // it, its blocks still in cache); a layer's from its tiles and a bin's from its
  // layers, a pass over the blocks each fewer. A box is kept in its bin's frame until
  // the parents have theirs (the union of the children's, the same as from the blocks);
  // a parent's cone holds its children's cones, so every member direction.
  struct Extent {
    Eigen::Vector3f low = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
    Eigen::Vector3f high = Eigen::Vector3f::Constant(-std::numeric_limits<float>::max());
    Eigen::Vector3f direction_sum = Eigen::Vector3f::Zero();  // turned towards the frame's axis
  };
  auto place = [&](Node& node, const Frame& frame, const Extent& extent) {
    node.axis = extent.direction_sum.normalized();
    const Eigen::Vector3f centre = 0.5F * (extent.low + extent.high);
    node.centre = frame.a * centre.x() + frame.u * centre.y() + frame.v * centre.z();
    // A little slack for the float rounding of the frame change.
    node.half_extent = 0.5F * (extent.high - extent.low) + Eigen::Vector3f::Constant(1e-5F);
  };
  auto fromBlocks = [&](Node& node, const Frame& frame) {
    Extent extent;
    for (std::uint32_t k = node.begin; k < node.end; ++k) {
      const Eigen::Vector3f& d = block_directions_[k];
      extent.direction_sum += d.dot(frame.a) < 0.0F ? Eigen::Vector3f(-d) : d;
      const Eigen::Vector3f q(frame.a.dot(points_[k]), frame.u.dot(points_[k]), frame.v.dot(points_[k]));
      extent.low = extent.low.cwiseMin(q);
      extent.high = extent.high.cwiseMax(q);
    }
    place(node, frame, extent);
    node.cos_radius = 1.0F;
    for (std::uint32_t k = node.begin; k < node.end; ++k) {
      node.cos_radius = std::min(node.cos_radius, std::abs(node.axis.dot(block_directions_[k])));
    }
    node.sin_radius = sineOf(node.cos_radius);
    return extent;
  };
  auto fromChildren = [&](Node& node, const Frame& frame, const std::vector<Node>& children,
                          const std::vector<Extent>& extents) {
    Extent extent;
    for (std::uint32_t c = node.begin; c < node.end; ++c) {
      extent.low = extent.low.cwiseMin(extents[c].low);
      extent.high = extent.high.cwiseMax(extents[c].high);
      extent.direction_sum += extents[c].direction_sum;
    }
    place(node, frame, extent);
    // A child's directions lie within its radius of its axis: within the angle from
    // this axis to that one plus the radius. Cosines of sums, a little less for rounding.
    node.cos_radius = 1.0F;
    for (std::uint32_t c = node.begin; c < node.end; ++c) {
      const float cos_apart = std::min(1.0F, std::abs(node.axis.dot(children[c].axis)));
      const float sin_apart = std::sqrt(std::max(0.0F, 1.0F - cos_apart * cos_apart));
      const float cos_child = children[c].cos_radius;
      const float sin_child = std::sqrt(std::max(0.0F, 1.0F - cos_child * cos_child));
      node.cos_radius = std::min(node.cos_radius, cos_apart * cos_child - sin_apart * sin_child - 1e-6F);
    }
    node.cos_radius = std::max(0.0F, node.cos_radius);
    node.sin_radius = sineOf(node.cos_radius);
    return extent;
  };
  const auto layer_count_signed = static_cast<std::int64_t>(layers_.size());
  const auto tile_count_signed = static_cast<std::int64_t>(tiles_.size());
  std::vector<Extent> tile_extents(tiles_.size());
  std::vector<Extent> layer_extents(layers_.size());
#pragma omp parallel num_threads(team) if (team > 1)
  {
#pragma omp for schedule(dynamic, 64)
    for (std::int64_t t = 0; t < tile_count_signed; ++t) {
      const auto tile = static_cast<std::size_t>(t);
      tile_extents[tile] = fromBlocks(tiles_[tile], frames_[bin_of_layer_[layer_of_tile_[tile]]]);
      sumTile(tiles_[tile]);
    }
#pragma omp for schedule(dynamic, 16)
    for (std::int64_t l = 0; l < layer_count_signed; ++l) {
      const auto layer = static_cast<std::size_t>(l);
      layer_extents[layer] = fromChildren(layers_[layer], frames_[bin_of_layer_[layer]], tiles_, tile_extents);
    }
  }
  for (std::size_t b = 0; b < bins; ++b) {
    if (bins_[b].begin != bins_[b].end) fromChildren(bins_[b], frames_[b], layers_, layer_extents);
  }
  live_tiles_.resize(tiles_.size());
  for (std::uint32_t t = 0; t < tiles_.size(); ++t) {
    const Node& tile = tiles_[t];
    live_tiles_[t] = LiveTile{tile.axis, tile.cos_radius, tile.centre, tile.sin_radius, tile.half_extent, t};
  }
  live_end_.resize(layers_.size());
  for (std::size_t l = 0; l < layers_.size(); ++l) live_end_[l] = layers_[l].end;
  std::vector<std::uint32_t> all_tiles(tiles_.size());
  for (std::uint32_t t = 0; t < tiles_.size(); ++t) all_tiles[t] = t;
  sumLayersAndBins(all_tiles);
}

}  // namespace mlmap
