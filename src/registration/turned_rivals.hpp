// Internal to alignVerified: the rivals of a result a quarter, a half and three quarters of a
// turn away. Rooms are nearly symmetric under those turns (most walls meet at right angles,
// a rectangle maps onto itself under a half turn, a square under a quarter), so a result
// turned so can explain enough of the overlap to pass verification on its own: a scan
// verified 165 cm and 90 deg off explained 20 % of its points, where the truth explains 41 %
// (register_ate.py, tuning room-1, seed 7, 30 deg drift, with the coarse extrapolation).
// Verification compares absolute figures; whether an answer is the answer needs its rivals.
#pragma once

#include <vector>

#include "mlmap/registration/icp.hpp"
#include "mlmap/registration/verified_icp.hpp"

namespace mlmap::registration {

struct TurnedRival {
  IcpResult icp;       // ICP from the result turned by turn_deg
  Verification check;  // verifyAlignment at icp.pose (no slide profile)
  double turn_deg = 0.0;
  bool ran = false;    // ICP ran (on a sample at least); check is empty unless the sample made it a rival
};

// For each of 90, 180 and 270 deg: `pose` (source -> target) turned about the vertical
// through the centre of the source's horizontal extent at `pose` (a room's centre where
// the scan sees its walls: the turn maps the room onto itself as nearly as its shape
// allows), one ICP run with `icp` from there, checked with (sigma, gate, config).
// A turn is run only when the source's wall points (by `normals`, the source's own) lie
// within icp.initial_max_distance of the target about as often turned as at `pose`.
// Turns that leave the result more than a quarter turn (and 10 deg) from `start` are not run.
std::vector<TurnedRival> turnedRivals(const std::vector<Point>& source, const std::vector<Eigen::Vector3d>& normals,
                                      const VoxelHashMap& target, const Pose& pose, const Pose& start,
                                      const IcpConfig& icp, double sigma, double gate, const BasinConfig& config);

// What the rivals say of a result that verified with `kept`.
struct RivalVerdict {
  const TurnedRival* best = nullptr;  // the best-explained rival that explains the overlap
  bool replaces = false;   // best explains more than 1 / rival_share of kept's points ...
  bool ambiguous = false;  // ... or at least rival_share of them, or (replacing) another rival
                           // comes within rival_share of best
};
RivalVerdict judgeRivals(const std::vector<TurnedRival>& rivals, const Verification& kept, const BasinConfig& config);

}  // namespace mlmap::registration
