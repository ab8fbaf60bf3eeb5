// Internal to eRMSM: the blocks grouped by the orientation of their direction
// vectors, so scoring a candidate plane reads only blocks whose direction can be
// within κ of its normal; and the score pass itself (surface units, section V).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "pca_sums.hpp"

namespace mlmap {

struct CandidatePlane {
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();  // unit
  Eigen::Vector3f point = Eigen::Vector3f::Zero();    // m, a point on the plane
};

struct PlaneScore {
  double score = 0.0;    // s_c: surface of the untaken blocks matching the plane
  double similar = 0.0;  // s_o: surface of the untaken blocks of similar direction
  PcaSums pca;           // of the matching blocks, relative to the plane's point (Algorithm 2)
};

class PlaneScorer {
 public:
  PlaneScorer(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
              double epsilon, double kappa_rad);

  PlaneScore score(const CandidatePlane& plane) const;
  // Ids of the untaken blocks matching the plane, ascending.
  std::vector<std::uint32_t> matching(const CandidatePlane& plane) const;
  bool matches(std::uint32_t id, const CandidatePlane& plane) const;

  void take(std::uint32_t id);
  bool taken(std::uint32_t id) const { return taken_[id] != 0; }

 private:
  // A bin's blocks side by side in memory (structure of arrays), so a score pass
  // streams through them instead of hopping around the block table.
  struct Bin {
    Eigen::Vector3f axis;  // unit centre of the bin
    std::vector<std::uint32_t> ids;
    std::vector<Eigen::Vector3f> points;
    std::vector<Eigen::Vector3f> directions;
    std::vector<float> surfaces;
    std::vector<float> half_depths;  // 0 for horizontal blocks
    std::vector<std::uint8_t> taken;
  };
  template <typename Visit>
  void forEachSimilar(const CandidatePlane& plane, Visit&& visit) const;

  const BlockGrid& grid_;
  const std::vector<Eigen::Vector3f>& directions_;
  float epsilon_;
  float cos_kappa_;
  float cos_bin_reach_;
  std::vector<Bin> bins_;
  std::vector<std::uint8_t> taken_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> slot_;  // block id -> (bin, index)
};

}  // namespace mlmap
