// Internal to alignVerified: the rivals of a result a quarter, a half and three quarters of a
// turn away (and where it lies beyond the start's bound, unturned at the start's place). Rooms are nearly symmetric under those turns (most walls meet at right angles,
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
  IcpResult icp;       // ICP from the result's heading turned by turn_deg, at the start's place
  Verification check;  // verifyAlignment at icp.pose (no slide profile)
  double turn_deg = 0.0;
  // Nearer the start's place than the result by more than max_start_translation: where the
  // result lies beyond the start's bound and a turned answer within it explains the overlap,
  // the result is no clearer than the rival, whatever their explained shares.
  bool nearer_start = false;
  // ... farther by as much: the start tells them apart, and the rival does not contend (in
  // the held-out symmetric room, from 20-30 deg off, a quarter turn 1.1 m away explained 43 %
  // against the truth's 26 % and replaced it).
  bool farther_start = false;
  bool within_start = false;  // within max_start_translation of the start's place
  bool ran = false;    // ICP ran (on a sample at least); check is empty unless the sample made it a rival
};

// For each of 90, 180 and 270 deg, and 0 where `pose` lies more than max_start_translation from
// the start's place: the result's heading turned so about the vertical, at the start's place
// (`start`'s translation; unturned, this finds a result slid along a corridor: the held-out
// corridor from 20-60 deg off, 2.5 m along it, explaining 23 % against the truth's 37 %), one ICP run with `icp` (its first gate at least 1 m)
// on a sample of the source, checked with (sigma, gate, config); on every point where the sample
// makes it a rival (it explains rival_share of what the result explains of the sample, or lies
// nearer the start). Turns not run: more than a quarter turn (and 10 deg) from `start`, or
// where the source's wall points (by `normals`, the source's own) lie within
// icp.initial_max_distance of the target much less often turned than at `pose`. A rival that
// ends within 0.1 m and 2 deg of `pose` is the result itself (check left empty).
std::vector<TurnedRival> turnedRivals(const std::vector<Point>& source, const std::vector<Eigen::Vector3d>& normals,
                                      const VoxelHashMap& target, const Pose& pose, const Pose& start,
                                      const IcpConfig& icp, double sigma, double gate, const BasinConfig& config);

// What the rivals say of a result that verified with `kept`. A rival contends when it explains
// the overlap, does not lie farther from the start, and either explains rival_share of kept's
// explained points or lies nearer the start.
struct RivalVerdict {
  const TurnedRival* best = nullptr;  // the best-explained contending rival
  bool replaces = false;   // best explains rival_replace times kept's points or more, within
                           // the start's bound ...
  bool ambiguous = false;  // ... or it does not, or (replacing) another rival contends with best
};
RivalVerdict judgeRivals(const std::vector<TurnedRival>& rivals, const Verification& kept, const BasinConfig& config);

}  // namespace mlmap::registration
