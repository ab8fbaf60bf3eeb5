#include "mlmap/registration/pose_graph.hpp"

#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>

#include "mlmap/error.hpp"

namespace mlmap::registration {
namespace {

// Each free pose moves by a left increment about its own position (world frame), which
// keeps rotations and translations decoupled however far the pose is from the origin.
Pose perturbed(const Pose& pose, const Vector6d& increment) {
  return applyIncrement(increment, pose.translation(), pose);
}

double totalCost(const std::vector<Pose>& poses, const std::vector<PoseGraphEdge>& edges) {
  double cost = 0.0;
  for (const PoseGraphEdge& edge : edges) {
    const Vector6d error = edgeError(edge, poses[edge.from], poses[edge.to]);
    cost += error.dot(edge.information * error);
  }
  return cost;
}

}  // namespace

Vector6d edgeError(const PoseGraphEdge& edge, const Pose& from, const Pose& to) {
  return incrementOf((from.inverse() * to) * edge.measurement.inverse(), edge.pivot);
}

PoseGraphResult optimizePoseGraph(std::vector<Pose>& poses, const std::vector<PoseGraphEdge>& edges,
                                  const PoseGraphConfig& config) {
  for (const PoseGraphEdge& edge : edges) {
    if (edge.from >= poses.size() || edge.to >= poses.size() || edge.from == edge.to) {
      throw Error("pose graph: edge " + std::to_string(edge.from) + " -> " + std::to_string(edge.to) +
                  " does not join two of the " + std::to_string(poses.size()) + " poses");
    }
  }
  PoseGraphResult result;
  result.initial_cost = result.final_cost = totalCost(poses, edges);
  if (poses.size() < 2 || edges.empty()) return result;

  const std::size_t free_count = poses.size() - 1;  // pose 0 is fixed; pose k is variable k − 1
  const auto dimension = static_cast<Eigen::Index>(6 * free_count);
  double damping = 1e-6;
  for (int iteration = 0; iteration < config.max_iterations; ++iteration) {
    result.iterations = iteration + 1;
    // Gauss–Newton system from numerical Jacobians (central differences of the 6×12
    // edge Jacobian; the graphs here have tens of edges, so this is cheap and exact enough).
    std::vector<Eigen::Triplet<double>> triplets;
    Eigen::VectorXd gradient = Eigen::VectorXd::Zero(dimension);
    constexpr double kStep = 1e-6;
    for (const PoseGraphEdge& edge : edges) {
      const Vector6d error = edgeError(edge, poses[edge.from], poses[edge.to]);
      Eigen::Matrix<double, 6, 12> jacobian;
      for (int k = 0; k < 12; ++k) {
        Vector6d delta = Vector6d::Zero();
        delta[k % 6] = kStep;
        const bool moves_from = k < 6;
        const Pose& from = poses[edge.from];
        const Pose& to = poses[edge.to];
        const Vector6d plus = moves_from ? edgeError(edge, perturbed(from, delta), to)
                                         : edgeError(edge, from, perturbed(to, delta));
        const Vector6d minus = moves_from ? edgeError(edge, perturbed(from, -delta), to)
                                          : edgeError(edge, from, perturbed(to, -delta));
        jacobian.col(k) = (plus - minus) / (2.0 * kStep);
      }
      const std::size_t nodes[2] = {edge.from, edge.to};
      for (int a = 0; a < 2; ++a) {
        if (nodes[a] == 0) continue;
        const auto row = static_cast<Eigen::Index>(6 * (nodes[a] - 1));
        const Eigen::Matrix<double, 6, 6> jta = jacobian.middleCols<6>(6 * a).transpose() * edge.information;
        gradient.segment<6>(row) += jta * error;
        for (int b = 0; b < 2; ++b) {
          if (nodes[b] == 0) continue;
          const auto col = static_cast<Eigen::Index>(6 * (nodes[b] - 1));
          const Matrix6d block = jta * jacobian.middleCols<6>(6 * b);
          for (int r = 0; r < 6; ++r) {
            for (int c = 0; c < 6; ++c) triplets.emplace_back(row + r, col + c, block(r, c));
          }
        }
      }
    }
    Eigen::SparseMatrix<double> hessian(dimension, dimension);
    hessian.setFromTriplets(triplets.begin(), triplets.end());

    // Levenberg–Marquardt: damp the diagonal until a step lowers the cost.
    bool improved = false;
    double largest_step = 0.0;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Eigen::SparseMatrix<double> damped = hessian;
      for (Eigen::Index i = 0; i < dimension; ++i) damped.coeffRef(i, i) *= 1.0 + damping;
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(damped);
      if (solver.info() != Eigen::Success) {
        damping *= 10.0;
        continue;
      }
      const Eigen::VectorXd step = solver.solve(-gradient);
      std::vector<Pose> candidate = poses;
      for (std::size_t k = 1; k < poses.size(); ++k) {
        candidate[k] = perturbed(poses[k], step.segment<6>(static_cast<Eigen::Index>(6 * (k - 1))));
      }
      const double cost = totalCost(candidate, edges);
      if (cost <= result.final_cost) {
        poses = std::move(candidate);
        result.final_cost = cost;
        largest_step = step.cwiseAbs().maxCoeff();
        damping = std::max(1e-9, damping / 10.0);
        improved = true;
      } else {
        damping *= 10.0;
      }
    }
    if (!improved || largest_step < config.min_step) break;
  }
  return result;
}

}  // namespace mlmap::registration
