// Internal to eRMSM: the score of a candidate plane (section V) — the surface, in
// surface units, of the untaken blocks within ε of the plane whose direction vectors
// lie within κ of its normal (s_c), and of all untaken blocks within κ (s_o, eq. 10).
//
// A pass over every block for every candidate costs most of the detection time on a
// fine map, so the blocks are indexed: by the orientation of their direction vectors
// (bins), inside a bin by their offset along the bin's axis (layers: slices ε/2 thick,
// consecutive sparse slices joined), inside a slice by position (tiles, a few cells
// wide). Every node knows the cone of its blocks' directions, the box of their points
// and the sums of its untaken blocks. A node whose cone lies within κ of the plane's
// normal and whose box lies within the slab |n·x + d| < ε counts whole; a node whose
// cone or box lies outside is skipped; only the nodes the cone or the slab's faces cut
// are opened. The result is the score of the paper's definition, block for block.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "fill_vector.hpp"
#include "id_set.hpp"
#include "pca_sums.hpp"

namespace mlmap {

struct CandidatePlane {
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();  // unit
  Eigen::Vector3f point = Eigen::Vector3f::Zero();    // m, a point on the plane
  // m, the plane's ε: blocks closer than this match it; 0 = the scorer's (its narrowest).
  // A candidate widens it up to ErmsmConfig::max_epsilon where its own blocks' spread
  // says the band cuts their noise (refitCandidate).
  float epsilon = 0.0F;
};

struct PlaneScore {
  double score = 0.0;    // s_c: surface of the untaken blocks matching the plane
  double similar = 0.0;  // s_o: surface of the untaken blocks of similar direction
  PcaSums pca;           // of the matching blocks, relative to the plane's point (Algorithm 2)
};

class PlaneScorer {
 public:
  // `threads`: OpenMP threads for building the index, 0 = OpenMP's default.
  PlaneScorer(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
              double epsilon, double kappa_rad, int threads = 0);

  PlaneScore score(const CandidatePlane& plane) const;
  // m, the plane's ε.
  float bandOf(const CandidatePlane& plane) const { return plane.epsilon > 0.0F ? plane.epsilon : epsilon_; }
  // Ids of the untaken blocks matching the plane, ascending.
  std::vector<std::uint32_t> matching(const CandidatePlane& plane) const;
  bool matches(std::uint32_t id, const CandidatePlane& plane) const;
  // Ids of the untaken blocks near the plane, ascending: within `reach` (m) of it, and
  // with a direction within the cone of cosine `cos_cone` about its normal or none. A
  // little wider than asked (float rounding): the caller applies its exact test.
  // With `with_matching`, also the blocks that match the plane (else the caller has them).
  std::vector<std::uint32_t> near(const CandidatePlane& plane, float cos_cone, float reach,
                                  bool with_matching = false) const;

  // Takes the blocks out of the pool (an accepted plane's); the nodes' sums follow.
  void take(const std::vector<std::uint32_t>& ids);
  bool taken(std::uint32_t id) const { return taken_[id] != 0; }

 private:
  // A bin, a layer or a tile: its children are a run of the next level (a tile's are
  // a run of the block arrays).
  struct Node {
    std::uint32_t begin = 0;
    std::uint32_t end = 0;
    Eigen::Vector3f axis = Eigen::Vector3f::UnitZ();  // unit mean direction of its blocks
    float cos_radius = 1.0F;                          // cosine of the widest member direction from the axis
    float sin_radius = 0.0F;                          // its sine (kept: every query's cone test needs it)
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();       // m, of its points' box
    Eigen::Vector3f half_extent = Eigen::Vector3f::Zero();  // m, of the box along its bin's frame
    std::uint32_t untaken = 0;
    double surface = 0.0;  // untaken surface
    PcaSums pca;           // untaken blocks, relative to centre
  };
  // What a query tests of a tile, for the tiles that still hold untaken blocks: a
  // score passes over half the tiles of a real scan's clutter, most of them taken or
  // outside, and these 48 bytes are what it reads of each.
  struct LiveTile {
    Eigen::Vector3f axis;
    float cos_radius;
    Eigen::Vector3f centre;
    float sin_radius;
    Eigen::Vector3f half_extent;
    std::uint32_t tile;  // index in tiles_
  };
  struct Frame {
    Eigen::Vector3f a, u, v;  // the bin's axis and two directions across it
  };
  enum class Cone { Outside, Cut, Inside };
  enum class Slab { Outside, Cut, Inside };
  struct Query;

  void sumTile(Node& tile) const;
  void refresh(const std::vector<std::uint32_t>& tiles);
  void sumLayersAndBins(const std::vector<std::uint32_t>& tiles);
  void dropTakenTiles(std::uint32_t layer);
  void collect(const Query& query, const Query* except, IdSet& ids) const;

  const BlockGrid& grid_;
  const std::vector<Eigen::Vector3f>& directions_;
  float epsilon_;
  float cos_kappa_;
  int team_ = 1;  // OpenMP threads for building and refreshing the index
  std::vector<Node> bins_;    // children: layers
  std::vector<Frame> frames_; // per bin
  std::vector<Node> layers_;  // children: tiles
  std::vector<Node> tiles_;   // children: blocks
  // A layer's untaken tiles, ascending, are live_tiles_[layers_[l].begin, live_end_[l]):
  // a tile once taken never returns, so each run only shrinks.
  std::vector<LiveTile> live_tiles_;
  std::vector<std::uint32_t> live_end_;  // per layer
  // Blocks ordered by bin, layer, tile, id (structure of arrays: a pass streams).
  FillVector<std::uint32_t> ids_;
  FillVector<Eigen::Vector3f> points_;
  FillVector<Eigen::Vector3f> block_directions_;
  FillVector<float> surfaces_;
  FillVector<float> half_depths_;  // 0 for horizontal blocks
  std::vector<std::uint8_t> order_taken_;
  std::vector<std::uint8_t> taken_;                 // by block id
  std::vector<std::uint32_t> position_;             // block id -> index in the arrays, UINT32_MAX for none
  std::vector<std::uint32_t> tile_of_;              // array index -> tile
  std::vector<std::uint32_t> layer_of_tile_;
  std::vector<std::uint32_t> bin_of_layer_;
  std::vector<std::uint32_t> undirected_;           // blocks without a direction (not in the index)
  std::vector<Eigen::Vector3f> undirected_points_;  // theirs: each accepted plane's edges pass over them
};

}  // namespace mlmap
