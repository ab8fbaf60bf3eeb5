// Internal to eRMSM, beyond the paper: an accepted wall's plane turned onto its blocks'
// directions.
//
// Algorithm 2 refits a candidate by least squares on the blocks within ε of it. Where two
// parallel surfaces a few centimetres apart stand side by side, the fit that holds most of
// both leans between them: PCL's room_scan2 at 10 cm cells, a wall and a cabinet front 8 cm
// proud of it became one patch on a plane turned 2° off the wall, which left the wall's far
// half beyond ε. The blocks' direction vectors, each from its own neighbourhood, still agree
// with the surfaces: their mean lies 2.1° from that plane's normal, 4.3 standard errors of
// itself (48 blocks spread 2.2°), where on that scan's walls that are one surface it lies
// 0.3-1.3° off, within 3 standard errors.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "plane_scorer.hpp"

namespace mlmap {

// For a plumb plane (its normal within `max_tilt_rad` of horizontal: walls; level planes'
// blocks turn with what lies on them) whose matching blocks `strict` disagree with it: (a) where
// their mean heading (the directions' azimuth) lies further from the normal's than
// kTurnStandardErrors standard errors of that mean and kMinTurn, the plane turned to that
// heading at its own lean; (b) where their mean 3-D direction (plumb, for walls' blocks) does,
// the plane turned onto it if that holds more untaken surface than the plane. Each through the
// layer of those blocks that holds the most surface (the ε-wide window of their offsets along
// it); of (a) and (b) the one holding more surface. None otherwise.
std::optional<CandidatePlane> alongDirections(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                                              const PlaneScorer& scorer, const std::vector<std::uint32_t>& strict,
                                              const CandidatePlane& plane, double max_tilt_rad);

}  // namespace mlmap
