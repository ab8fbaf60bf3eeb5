// PlaneScorer's sums (plane_scorer.hpp): each node's untaken blocks' count, surface and
// moments, kept as accepted planes take blocks out of the pool. The index they sum over
// is built in plane_scorer_index.cpp.
#include <atomic>
#include <cstdint>
#include <vector>

#include "plane_scorer.hpp"

namespace mlmap {
namespace {

// Refresh fewer tiles than this on one thread.
constexpr std::int64_t kParallelTiles = 64;
// ... and take fewer blocks than this on one thread.
constexpr std::int64_t kParallelTakes = 20000;

}  // namespace

// The sums of the tile's untaken blocks.
void PlaneScorer::sumTile(Node& tile) const {
  tile.untaken = 0;
  tile.surface = 0.0;
  tile.pca = PcaSums{};
  for (std::uint32_t k = tile.begin; k < tile.end; ++k) {
    if (order_taken_[k] != 0) continue;
    ++tile.untaken;
    tile.surface += surfaces_[k];
    tile.pca.addBlock((points_[k] - tile.centre).cast<double>(), half_depths_[k], surfaces_[k]);
  }
}

// Recomputes the sums of the given tiles (ascending) and of their layers and bins.
void PlaneScorer::refresh(const std::vector<std::uint32_t>& tiles) {
  // Each tile on its own: a floor's take refreshes a thousand tiles of 150 blocks.
  const auto count = static_cast<std::int64_t>(tiles.size());
#pragma omp parallel for schedule(dynamic, 16) num_threads(team_) if (team_ > 1 && count > kParallelTiles)
  for (std::int64_t n = 0; n < count; ++n) sumTile(tiles_[tiles[static_cast<std::size_t>(n)]]);
  sumLayersAndBins(tiles);
}

namespace {

// A parent's sums from its children's [begin, end), each shifted to the parent's centre.
template <typename Node>
void sumChildren(Node& parent, const std::vector<Node>& children) {
  parent.untaken = 0;
  parent.surface = 0.0;
  parent.pca = PcaSums{};
  for (std::uint32_t c = parent.begin; c < parent.end; ++c) {
    parent.untaken += children[c].untaken;
    parent.surface += children[c].surface;
    parent.pca.addShifted(children[c].pca, (children[c].centre - parent.centre).template cast<double>());
  }
}

}  // namespace

// The sums of the layers and bins of the given tiles (ascending), from their tiles'.
void PlaneScorer::sumLayersAndBins(const std::vector<std::uint32_t>& tiles) {
  std::vector<std::uint32_t> layers;
  for (const std::uint32_t t : tiles) {
    if (layers.empty() || layers.back() != layer_of_tile_[t]) layers.push_back(layer_of_tile_[t]);
  }
  std::vector<std::uint32_t> bins;
  for (const std::uint32_t l : layers) {
    sumChildren(layers_[l], tiles_);
    dropTakenTiles(l);
    if (bins.empty() || bins.back() != bin_of_layer_[l]) bins.push_back(bin_of_layer_[l]);
  }
  for (const std::uint32_t b : bins) sumChildren(bins_[b], layers_);
}

// Keeps the layer's live run to the tiles that still hold untaken blocks, in order.
void PlaneScorer::dropTakenTiles(std::uint32_t layer) {
  std::uint32_t kept = layers_[layer].begin;
  for (std::uint32_t n = layers_[layer].begin; n < live_end_[layer]; ++n) {
    if (tiles_[live_tiles_[n].tile].untaken != 0) live_tiles_[kept++] = live_tiles_[n];
  }
  live_end_[layer] = kept;
}

void PlaneScorer::take(const std::vector<std::uint32_t>& ids) {
  // The dirty tiles as a byte each: sorting a tile per taken block (150 000 for a floor
  // at 2 cm) cost more than refreshing them. A floor's blocks on all threads: each
  // block's flags are its own, and a tile marked twice is marked with the same byte.
  std::vector<std::uint8_t> dirty(tiles_.size(), 0);
  const auto count = static_cast<std::int64_t>(ids.size());
#pragma omp parallel for schedule(static) num_threads(team_) if (team_ > 1 && count > kParallelTakes)
  for (std::int64_t n = 0; n < count; ++n) {
    const std::uint32_t id = ids[static_cast<std::size_t>(n)];
    taken_[id] = 1;
    const std::uint32_t k = position_[id];
    if (k == UINT32_MAX) continue;
    order_taken_[k] = 1;
    std::atomic_ref<std::uint8_t>(dirty[tile_of_[k]]).store(1, std::memory_order_relaxed);
  }
  std::vector<std::uint32_t> tiles;
  for (std::uint32_t t = 0; t < dirty.size(); ++t) {
    if (dirty[t] != 0) tiles.push_back(t);
  }
  refresh(tiles);
}

}  // namespace mlmap
