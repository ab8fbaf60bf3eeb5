// PlaneScorer's queries (plane_scorer.hpp): a candidate's score, its matching blocks
// and the blocks near it, each a walk of the index built in plane_scorer_index.cpp.
#include "plane_scorer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "id_set.hpp"

namespace mlmap {
namespace {

// Cones closer than this to κ are decided block by block (float rounding).
constexpr float kCosMargin = 1e-5F;

}  // namespace

// The plane against a node: the cone of its directions against κ, its box against the slab.
struct PlaneScorer::Query {
  Eigen::Vector3f normal;
  float offset;
  float cos_kappa;
  float epsilon;

  template <typename NodeT>
  Cone cone(const NodeT& node) const {
    const float cos_t = std::min(1.0F, std::abs(node.axis.dot(normal)));
    const float sin_t = std::sqrt(std::max(0.0F, 1.0F - cos_t * cos_t));
    const float cos_r = node.cos_radius;
    const float sin_r = node.sin_radius;
    if (cos_t * cos_r - sin_t * sin_r > cos_kappa + kCosMargin) return Cone::Inside;  // t + ρ < κ
    if (cos_t < cos_r && cos_t * cos_r + sin_t * sin_r < cos_kappa - kCosMargin) return Cone::Outside;  // t − ρ > κ
    return Cone::Cut;
  }
  template <typename NodeT>
  Slab slab(const NodeT& node, const Eigen::Vector3f& frame_normal) const {
    const float distance = std::abs(normal.dot(node.centre) + offset);
    const float radius = frame_normal.dot(node.half_extent);
    if (distance - radius >= epsilon) return Slab::Outside;
    if (distance + radius < epsilon) return Slab::Inside;
    return Slab::Cut;
  }
};

PlaneScore PlaneScorer::score(const CandidatePlane& plane) const {
  PlaneScore result;
  const Query query{plane.normal, -plane.normal.dot(plane.point), cos_kappa_, bandOf(plane)};
  const Eigen::Vector3d origin = plane.point.cast<double>();
  auto whole = [&](const Node& node) {
    result.score += node.surface;
    result.pca.addShifted(node.pca, node.centre.cast<double>() - origin);
  };
  auto blocks = [&](const Node& tile, Cone cone, Slab slab) {
    for (std::uint32_t k = tile.begin; k < tile.end; ++k) {
      if (order_taken_[k] != 0) continue;
      if (cone != Cone::Inside) {
        if (std::abs(block_directions_[k].dot(query.normal)) < cos_kappa_) continue;
        result.similar += surfaces_[k];
        if (slab == Slab::Outside) continue;
      }
      if (std::abs(query.normal.dot(points_[k]) + query.offset) >= query.epsilon) continue;
      result.score += surfaces_[k];
      result.pca.addBlock((points_[k] - plane.point).cast<double>(), half_depths_[k], surfaces_[k]);
    }
  };
  // Decides a node from its parent's verdicts; returns false when nothing inside remains to open.
  // `shape`: the node itself, or a live tile's copy of its cone and box.
  auto decide = [&](const auto& shape, const Node& node, const Eigen::Vector3f& frame_normal, Cone& cone, Slab& slab) {
    // A live tile has untaken blocks (and its node need not be read unless counted).
    if constexpr (!std::is_same_v<std::decay_t<decltype(shape)>, LiveTile>) {
      if (node.untaken == 0) return false;
    }
    if (cone == Cone::Cut) cone = query.cone(shape);
    if (cone == Cone::Outside) return false;
    if (slab == Slab::Cut) slab = query.slab(shape, frame_normal);
    if (cone == Cone::Inside) {
      result.similar += node.surface;
      if (slab == Slab::Outside) return false;
      if (slab == Slab::Inside) {
        whole(node);
        return false;
      }
    }
    return true;
  };
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    if (bins_[b].untaken == 0) continue;  // most bins: no direction falls in them, or all taken
    const Frame& frame = frames_[b];
    const Eigen::Vector3f frame_normal(std::abs(frame.a.dot(query.normal)), std::abs(frame.u.dot(query.normal)),
                                       std::abs(frame.v.dot(query.normal)));
    Cone bin_cone = Cone::Cut;
    Slab bin_slab = Slab::Cut;
    if (!decide(bins_[b], bins_[b], frame_normal, bin_cone, bin_slab)) continue;
    for (std::uint32_t l = bins_[b].begin; l < bins_[b].end; ++l) {
      Cone layer_cone = bin_cone;
      Slab layer_slab = bin_slab;
      // Counted whole already: a node inside the cone adds its s_o once, at the top.
      if (bin_cone == Cone::Inside && layer_slab == Slab::Cut) {
        const Node& layer = layers_[l];
        if (layer.untaken == 0) continue;
        layer_slab = query.slab(layer, frame_normal);
        if (layer_slab == Slab::Outside) continue;
        if (layer_slab == Slab::Inside) {
          whole(layer);
          continue;
        }
      } else if (!decide(layers_[l], layers_[l], frame_normal, layer_cone, layer_slab)) {
        continue;
      }
      // The untaken tiles only: the others add nothing.
      for (std::uint32_t n = layers_[l].begin; n < live_end_[l]; ++n) {
        Cone tile_cone = layer_cone;
        Slab tile_slab = layer_slab;
        const LiveTile& live = live_tiles_[n];
        if (layer_cone == Cone::Inside) {
          if (tile_slab == Slab::Cut) tile_slab = query.slab(live, frame_normal);
          if (tile_slab == Slab::Outside) continue;
          if (tile_slab == Slab::Inside) {
            whole(tiles_[live.tile]);
            continue;
          }
        } else if (!decide(live, tiles_[live.tile], frame_normal, tile_cone, tile_slab)) {
          continue;
        }
        blocks(tiles_[live.tile], tile_cone, tile_slab);
      }
    }
  }
  return result;
}

bool PlaneScorer::matches(std::uint32_t id, const CandidatePlane& plane) const {
  if (taken_[id] != 0 || directions_[id].squaredNorm() == 0.0F) return false;
  if (std::abs(directions_[id].dot(plane.normal)) < cos_kappa_) return false;
  return std::abs(plane.normal.dot(grid_.blocks()[id].point - plane.point)) < bandOf(plane);
}

std::vector<std::uint32_t> PlaneScorer::matching(const CandidatePlane& plane) const {
  IdSet ids(grid_.size());
  collect(Query{plane.normal, -plane.normal.dot(plane.point), cos_kappa_, bandOf(plane)}, nullptr, ids);
  return ids.ascending();
}

std::vector<std::uint32_t> PlaneScorer::near(const CandidatePlane& plane, float cos_cone, float reach,
                                             bool with_matching) const {
  // A little wider than asked: n·p + d here, where callers test n·(p − q) (another rounding).
  constexpr float kSlack = 1e-4F;
  IdSet ids(grid_.size());
  const Query query{plane.normal, -plane.normal.dot(plane.point), cos_cone - kSlack, reach + kSlack};
  // Tiles whose blocks all match the plane are left out: the caller has those.
  const Query matching{plane.normal, query.offset, cos_kappa_, bandOf(plane)};
  collect(query, with_matching ? nullptr : &matching, ids);
  for (std::size_t n = 0; n < undirected_.size(); ++n) {
    const std::uint32_t id = undirected_[n];
    if (std::abs(query.normal.dot(undirected_points_[n]) + query.offset) < query.epsilon && taken_[id] == 0) {
      ids.insert(id);
    }
  }
  return ids.ascending();
}

// The untaken indexed blocks within the query's cone and slab, but for tiles wholly
// inside `except`'s (when given).
void PlaneScorer::collect(const Query& query, const Query* except, IdSet& ids) const {
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    const Node& bin = bins_[b];
    if (bin.untaken == 0) continue;
    const Frame& frame = frames_[b];
    const Eigen::Vector3f frame_normal(std::abs(frame.a.dot(query.normal)), std::abs(frame.u.dot(query.normal)),
                                       std::abs(frame.v.dot(query.normal)));
    if (query.cone(bin) == Cone::Outside || query.slab(bin, frame_normal) == Slab::Outside) continue;
    for (std::uint32_t l = bin.begin; l < bin.end; ++l) {
      const Node& layer = layers_[l];
      if (layer.untaken == 0 || query.slab(layer, frame_normal) == Slab::Outside) continue;
      for (std::uint32_t n = layer.begin; n < live_end_[l]; ++n) {
        const LiveTile& live = live_tiles_[n];
        if (query.slab(live, frame_normal) == Slab::Outside) continue;
        const Cone cone = query.cone(live);
        if (cone == Cone::Outside) continue;
        if (except != nullptr && except->cone(live) == Cone::Inside && except->slab(live, frame_normal) == Slab::Inside) {
          continue;
        }
        const Node& tile = tiles_[live.tile];
        for (std::uint32_t k = tile.begin; k < tile.end; ++k) {
          if (order_taken_[k] != 0) continue;
          if (cone == Cone::Cut && std::abs(block_directions_[k].dot(query.normal)) < query.cos_kappa) continue;
          if (std::abs(query.normal.dot(points_[k]) + query.offset) < query.epsilon) ids.insert(ids_[k]);
        }
      }
    }
  }
}

}  // namespace mlmap
