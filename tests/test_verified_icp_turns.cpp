// alignVerified against its turned rivals (turned_rivals.hpp): far, turned starts in square
// and near-square rooms, where a result a quarter turn off explained enough to be verified.
#include <doctest/doctest.h>

#include <string>

#include "mlmap/registration/verified_icp.hpp"
#include "verified_pairs.hpp"

namespace {

using namespace mlmap::registration;
using namespace mlmap::test;

// A 7.4 × 7 × 3 m room with a cabinet and a low box, 1 cm noise: nearly square, so a quarter
// turn about its centre puts three walls within 0.2 m of where walls are.
const char* const kNearSquareRoomJson = R"({
  "scan_pattern": {"angular_step_deg": 1.0, "tilt_start_deg": -50, "tilt_end_deg": 50,
                   "tilt_step_deg": 2.0, "range_sigma": 0.01, "mount_height": 1.2},
  "poses": [{"x": 3.2, "y": 3.6, "yaw_deg": 15}, {"x": 4.0, "y": 3.1, "yaw_deg": 50}],
  "surfaces": [
    {"type": "rectangle", "class": "floor", "min": [0, 0, 0], "max": [7.4, 7, 0]},
    {"type": "rectangle", "class": "ceiling", "min": [0, 0, 3], "max": [7.4, 7, 3]},
    {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [0, 7, 3]},
    {"type": "rectangle", "class": "wall", "min": [7.4, 0, 0], "max": [7.4, 7, 3]},
    {"type": "rectangle", "class": "wall", "min": [0, 0, 0], "max": [7.4, 0, 3]},
    {"type": "rectangle", "class": "wall", "min": [0, 7, 0], "max": [7.4, 7, 3]},
    {"type": "box", "class": "other", "min": [0.2, 5.6, 0], "max": [1.0, 6.8, 2.0]},
    {"type": "box", "class": "other", "min": [5.8, 0.4, 0], "max": [6.6, 1.0, 0.8]}
  ]
})";

bool right(const VerifiedIcp& result, const Pose& truth) {
  return translationError(result.icp.pose, truth) < 0.02 && rotationErrorDeg(result.icp.pose, truth) < 0.5;
}

}  // namespace

TEST_CASE("alignVerified: a quarter turn off is not verified in a near-square room") {
  // From starts 60-90 deg off (beyond the 30 deg the retries reach) ICP stops a quarter turn
  // off, 58 cm from the truth, where the walls, floor and ceiling explain 30 % or 46 % of the
  // points (the truth: 59 %), and before the rivals that was verified. Its rival a quarter turn
  // back now replaces it where it explains at least 1.5 times as much (from 60 and 90 deg),
  // and makes it ambiguous where it does not (from -60 and -90 deg).
  const Pair pair = simulatedPair(kNearSquareRoomJson);
  for (const double yaw : {90.0, 60.0, -60.0, -90.0}) {
    CAPTURE(yaw);
    const VerifiedIcp result = alignVerified(pair.source, pair.target, startOff(pair.true_pose, {0.2, -0.1, 0.0}, yaw));
    CAPTURE(result.reason);
    CHECK((right(result, pair.true_pose) || !result.verified));
    CHECK(result.reason.empty() == result.verified);
  }
  // From within the retries' reach the truth is found and stays verified: its rivals explain
  // 0.78 of its points at most.
  const VerifiedIcp near = alignVerified(pair.source, pair.target, startOff(pair.true_pose, {0.2, -0.1, 0.0}, 25.0));
  CHECK(near.verified);
  CHECK(right(near, pair.true_pose));
}

TEST_CASE("alignVerified: a square room turned a quarter turn is ambiguous, not verified wrong") {
  // An empty square room is the same room turned by 90 deg: from 45-90 deg off ICP ends at the
  // turned room, 1 m from the truth, and explains more of the points there (66 %) than at the
  // truth (58 %: the target's scan covers the turned room's walls better). Before the rivals
  // each was verified; the rival a quarter turn away explains as much: ambiguous.
  const Pair pair = simulatedPair(kSymmetricRoomJson);
  for (const double yaw : {-45.0, -60.0, -90.0}) {
    CAPTURE(yaw);
    const VerifiedIcp result = alignVerified(pair.source, pair.target, startOff(pair.true_pose, {0.2, -0.1, 0.0}, yaw));
    CAPTURE(result.reason);
    CHECK((right(result, pair.true_pose) || !result.verified));
    if (!right(result, pair.true_pose)) CHECK(result.ambiguous);
  }
}
