// Pose graph: recovers a loop of poses from exact relative measurements, keeps pose 0.
#include <doctest/doctest.h>

#include <numbers>

#include "mlmap/error.hpp"
#include "mlmap/registration/pose_graph.hpp"

using mlmap::Pose;
using namespace mlmap::registration;

namespace {

Pose pose(double x, double y, double z, double yaw_deg, double roll_deg = 0.0) {
  Pose result = Pose::Identity();
  result.linear() = (Eigen::AngleAxisd(yaw_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(roll_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitX()))
                        .toRotationMatrix();
  result.translation() << x, y, z;
  return result;
}

}  // namespace

TEST_CASE("Pose graph: exact edges bring perturbed poses back, the first pose stays") {
  const std::vector<Pose> truth = {pose(20, 5, 1.2, 10), pose(22, 5.5, 1.2, 40), pose(23, 8, 1.25, 95, 1),
                                   pose(20.5, 9, 1.2, 170)};
  std::vector<PoseGraphEdge> edges;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    for (std::size_t j = i + 1; j < truth.size(); ++j) {
      PoseGraphEdge edge;
      edge.from = i;
      edge.to = j;
      edge.measurement = truth[i].inverse() * truth[j];
      edge.pivot = edge.measurement.translation();
      edge.information = Matrix6d::Identity() * (j == i + 1 ? 100.0 : 10.0);
      edges.push_back(edge);
    }
  }
  std::vector<Pose> poses = truth;
  poses[1] = pose(22.3, 5.2, 1.1, 45);
  poses[2] = pose(23.4, 7.5, 1.3, 85, -2);
  poses[3] = pose(20.0, 9.6, 1.2, 160);
  const PoseGraphResult result = optimizePoseGraph(poses, edges);
  CHECK(result.final_cost < 1e-12);
  CHECK(result.initial_cost > 1.0);
  CHECK(poses[0].isApprox(truth[0]));
  for (std::size_t i = 1; i < truth.size(); ++i) {
    CAPTURE(i);
    CHECK((poses[i].translation() - truth[i].translation()).norm() < 1e-6);
    CHECK((poses[i].linear() - truth[i].linear()).norm() < 1e-6);
  }
}

TEST_CASE("Pose graph: edge errors vanish at the measurement, bad edges throw") {
  PoseGraphEdge edge;
  edge.from = 0;
  edge.to = 1;
  edge.measurement = pose(1, 2, 0, 30);
  edge.pivot << 1, 2, 0;
  CHECK(edgeError(edge, pose(5, 5, 1, 20), pose(5, 5, 1, 20) * edge.measurement).norm() < 1e-12);
  std::vector<Pose> poses(2, Pose::Identity());
  edge.to = 2;
  CHECK_THROWS_AS(optimizePoseGraph(poses, {edge}), mlmap::Error);
}
