// Multi-pose mapping on a small simulated room with odometry drift: the corrected poses
// land within the 2 cm / 0.3° of the true ones.
#include <doctest/doctest.h>

#include "mlmap/registration/sequence_registration.hpp"
#include "mlmap/registration/trajectory_error.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"
#include "room_scenes.hpp"

using namespace mlmap::registration;

TEST_CASE("SequenceRegistration: scan-to-map and refinement correct drifting odometry") {
  const mlmap::sim::Scene scene = mlmap::sim::parseScene(mlmap::test::kRoomsJson, "rooms.json");
  const auto scans = mlmap::sim::simulate(scene);
  std::vector<mlmap::Pose> truth;
  std::vector<mlmap::Pose> odometry;
  SequenceRegistration sequence;
  for (const auto& scan : scans) {
    const IcpResult result = sequence.addScan(scan.scan.points, scan.odometry_pose);
    CHECK_FALSE(result.unreliable);
    truth.push_back(scan.true_pose);
    odometry.push_back(scan.odometry_pose);
  }
  const TrajectoryError before = trajectoryError(odometry, truth);
  CHECK(before.max_translation > 0.05);  // the drift is real
  const TrajectoryError sequential = trajectoryError(sequence.poses(), truth);
  CHECK(sequential.max_translation < 0.02);
  CHECK(sequential.max_rotation_deg < 0.3);

  const RefinementResult refinement = sequence.refine();
  CHECK(refinement.pair_edges >= 1);
  CHECK(refinement.graph.final_cost <= refinement.graph.initial_cost);
  const TrajectoryError refined = trajectoryError(sequence.poses(), truth);
  CHECK(refined.max_translation < 0.02);
  CHECK(refined.max_rotation_deg < 0.3);
  CHECK(sequence.poses()[0].isApprox(scans[0].odometry_pose));
}
