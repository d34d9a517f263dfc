#include "dynorb/optimization/pose_graph.h"

#include <ceres/ceres.h>

#include <array>

namespace dynorb {
namespace {

struct RelativePoseCost {
  RelativePoseCost(const Rigid3d& measured_b_from_a, double weight)
      : a_from_b_measured(measured_b_from_a.Inverse()), weight(weight) {}

  template <typename T>
  bool operator()(const T* qa, const T* ta, const T* qb, const T* tb, T* residual) const {
    using Quat = Eigen::Quaternion<T>;
    using Vec3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Quat> rot_a(qa), rot_b(qb);
    const Eigen::Map<const Vec3> trans_a(ta), trans_b(tb);
    // b_from_a = T_b * T_a^-1
    const Quat rot_a_inv = rot_a.conjugate();
    const Quat rot_ba = rot_b * rot_a_inv;
    const Vec3 trans_ba = trans_b - rot_ba * trans_a;
    // error = measured^-1 * estimate
    const Quat rot_m = a_from_b_measured.rotation.template cast<T>();
    const Vec3 trans_m = a_from_b_measured.translation.template cast<T>();
    Quat rot_err = rot_m * rot_ba;
    const Vec3 trans_err = rot_m * trans_ba + trans_m;
    if (rot_err.w() < T(0)) rot_err.coeffs() = -rot_err.coeffs();
    for (int i = 0; i < 3; ++i) {
      residual[i] = T(weight) * trans_err[i];
      residual[3 + i] = T(2.0 * weight) * rot_err.vec()[i];
    }
    return true;
  }

  Rigid3d a_from_b_measured;
  double weight;
};

}  // namespace

PoseGraphResult OptimizePoseGraph(std::map<uint64_t, Rigid3d>* cam_from_world,
                                  const std::vector<PoseGraphEdge>& edges,
                                  const std::set<uint64_t>& fixed,
                                  const PoseGraphOptions& options) {
  struct Block {
    std::array<double, 4> q;  // x, y, z, w (Eigen order)
    std::array<double, 3> t;
  };
  std::map<uint64_t, Block> blocks;
  for (const auto& [id, pose] : *cam_from_world) {
    const Eigen::Quaterniond q = pose.rotation.normalized();
    blocks[id] = {{q.x(), q.y(), q.z(), q.w()},
                  {pose.translation.x(), pose.translation.y(), pose.translation.z()}};
  }
  ceres::Problem problem;
  for (const PoseGraphEdge& e : edges) {
    auto a = blocks.find(e.a), b = blocks.find(e.b);
    if (a == blocks.end() || b == blocks.end() || e.a == e.b) continue;
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<RelativePoseCost, 6, 4, 3, 4, 3>(
                                 new RelativePoseCost(e.b_from_a, e.weight)),
                             nullptr, a->second.q.data(), a->second.t.data(), b->second.q.data(),
                             b->second.t.data());
  }
  PoseGraphResult result;
  for (auto& [id, block] : blocks) {
    if (!problem.HasParameterBlock(block.q.data())) continue;
    problem.SetManifold(block.q.data(), new ceres::EigenQuaternionManifold());
    if (fixed.count(id)) {
      problem.SetParameterBlockConstant(block.q.data());
      problem.SetParameterBlockConstant(block.t.data());
    }
  }
  if (problem.NumResidualBlocks() == 0) return result;
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = static_cast<int>(summary.iterations.size());
  for (auto& [id, block] : blocks) {
    const Eigen::Quaterniond q(block.q[3], block.q[0], block.q[1], block.q[2]);
    (*cam_from_world)[id] = Rigid3d(q, Eigen::Vector3d(block.t[0], block.t[1], block.t[2]));
  }
  return result;
}

}  // namespace dynorb
