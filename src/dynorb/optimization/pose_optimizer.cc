#include "dynorb/optimization/pose_optimizer.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/sized_cost_function.h>
#include <ceres/solver.h>
#include <glog/logging.h>

#include "dynorb/core/error.h"
#include "dynorb/optimization/pose_block.h"
#include "dynorb/optimization/robust_problem.h"

namespace dynorb {

namespace {

// (centre - prior) / sigma with centre = -R^T t. Tangent Jacobian (pose_block.h: t <- t + dt,
// R <- R Exp(dtheta)): d centre / dt = -R^T, d centre / dtheta = [centre]_x.
class CentrePriorCost final : public ceres::SizedCostFunction<3, kPoseBlockSize> {
 public:
  explicit CentrePriorCost(const CentrePrior& prior) : prior_(prior) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Rigid3d cam_from_world = FromPoseBlock(parameters[0]);
    const Eigen::Matrix3d world_from_cam_rotation =
        cam_from_world.rotation.toRotationMatrix().transpose();
    const Eigen::Vector3d centre = -(world_from_cam_rotation * cam_from_world.translation);
    const double inv_sigma = 1.0 / prior_.sigma_m;
    Eigen::Map<Eigen::Vector3d> r(residuals);
    r = inv_sigma * (centre - prior_.centre_in_world);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, kPoseBlockSize, Eigen::RowMajor>> j(jacobians[0]);
      j.setZero();
      j.block<3, 3>(0, 0) = -inv_sigma * world_from_cam_rotation;
      Eigen::Matrix3d skew;
      skew << 0.0, -centre.z(), centre.y(), centre.z(), 0.0, -centre.x(), -centre.y(), centre.x(),
          0.0;
      j.block<3, 3>(0, 3) = inv_sigma * skew;
    }
    return true;
  }

 private:
  CentrePrior prior_;
};

// The observation's pixel only (u_r < 0: monocular).
KeypointObservation WithoutDepth(KeypointObservation keypoint) {
  keypoint.u_right = -1.0;
  return keypoint;
}

// ORB-SLAM2's 95 % chi^2 gate of an observation (2 or 3 dof).
double NominalGate(const PoseObservation& obs, const PoseOptimizerOptions& options) {
  return obs.keypoint.IsStereo() ? options.chi2_stereo : options.chi2_mono;
}

// The gates' scale from the observations inside the nominal gates after the first round
// (PoseOptimizerOptions::min_gate_scale); 1 when too few.
double MeasuredGateScale(const std::vector<PoseObservation>& observations,
                         const std::vector<double>& chi2, const PoseOptimizerOptions& options) {
  std::vector<double> inside;
  std::vector<int> dof;
  for (size_t i = 0; i < observations.size(); ++i) {
    if (chi2[i] > NominalGate(observations[i], options)) continue;
    inside.push_back(chi2[i]);
    dof.push_back(observations[i].keypoint.IsStereo() ? 3 : 2);
  }
  const std::optional<double> scale = EstimateNoiseScale(inside, dof);
  return scale ? std::clamp(*scale, options.min_gate_scale, 1.0) : 1.0;
}

}  // namespace

ceres::CostFunction* NewCentrePriorCost(const CentrePrior& prior) {
  CHECK(prior.sigma_m > 0.0 && prior.huber_sigmas > 0.0)
      << "centre prior: sigma and Huber width > 0";
  return new CentrePriorCost(prior);
}

void PoseOptimizerOptions::Validate() const {
  if (num_rounds < 1 || iterations_per_round < 1 || robust_rounds < 0 || chi2_mono <= 0.0 ||
      chi2_stereo <= 0.0 || min_established < 0 ||
      !(provisional_gate_factor > 0.0 && provisional_gate_factor <= 1.0) ||
      !(min_gate_scale > 0.0 && min_gate_scale <= 1.0)) {
    throw InputError(
        "pose optimizer: rounds/iterations must be >= 1, chi2 gates > 0, provisional_gate_factor "
        "and min_gate_scale in (0, 1]");
  }
}

std::optional<double> EstimateNoiseScale(const std::vector<double>& chi2,
                                         const std::vector<int>& dof) {
  CHECK_EQ(chi2.size(), dof.size());
  constexpr int kMinValues = 20;
  if (static_cast<int>(chi2.size()) < kMinValues) return std::nullopt;
  // Medians of the chi^2 distribution with 2 (2 ln 2) and 3 degrees of freedom.
  constexpr double kMedian2 = 1.3862944, kMedian3 = 2.3659739;
  std::vector<double> ratio(chi2.size());
  for (size_t i = 0; i < chi2.size(); ++i) {
    CHECK(dof[i] == 2 || dof[i] == 3) << "observations have 2 or 3 dof";
    ratio[i] = chi2[i] / (dof[i] == 3 ? kMedian3 : kMedian2);
  }
  const auto middle = ratio.begin() + static_cast<std::ptrdiff_t>(ratio.size() / 2);
  std::nth_element(ratio.begin(), middle, ratio.end());
  return *middle;
}

PoseOptimizerResult OptimizePose(const PinholeCamera& camera, double bf,
                                 const std::vector<PoseObservation>& observations,
                                 const Rigid3d& initial_cam_from_world,
                                 const PoseOptimizerOptions& options, const CentrePrior* prior) {
  PoseOptimizerResult result;
  result.cam_from_world = initial_cam_from_world;
  result.inlier.assign(observations.size(), true);
  if (observations.empty()) return result;

  PoseBlock pose = ToPoseBlock(initial_cam_from_world);
  // One problem for all rounds: Huber kernels behind wrappers (switched to L2 after the robust
  // rounds); each round removes the blocks of new outliers and re-adds returning inliers.
  StagedLosses losses(options.chi2_mono, options.chi2_stereo);
  std::unique_ptr<ceres::HuberLoss>
      prior_loss;  // Outlives the problem (which does not own losses).
  if (prior != nullptr) prior_loss = std::make_unique<ceres::HuberLoss>(prior->huber_sigmas);
  ceres::Problem problem(StagedProblemOptions());
  problem.AddParameterBlock(pose.data(), kPoseBlockSize, NewPoseManifold());
  std::vector<ceres::ResidualBlockId> blocks(observations.size(), nullptr);
  if (prior != nullptr)
    problem.AddResidualBlock(NewCentrePriorCost(*prior), prior_loss.get(), pose.data());
  const int prior_blocks = prior != nullptr ? 1 : 0;
  ceres::Solver::Options solver_options;
  // Six unknowns: the normal equations are tiny and well conditioned, Cholesky beats QR.
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = options.iterations_per_round;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;

  int established = 0;
  for (const PoseObservation& obs : observations) established += obs.provisional ? 0 : 1;
  const bool hold_back_provisional = established >= options.min_established && options.robust_rounds > 0 &&
                                     options.robust_rounds < options.num_rounds;

  std::vector<double> chi2(observations.size());
  // Per observation: whether it takes part without its depth, and how its current block was built.
  result.depth_dropped.assign(observations.size(), false);
  std::vector<bool> block_without_depth(observations.size(), false);
  for (int round = 0; round < options.num_rounds; ++round) {
    if (round == options.robust_rounds) {
      losses.SwitchToL2();
    }
    for (size_t i = 0; i < observations.size(); ++i) {
      const bool wanted = result.inlier[i] && !(hold_back_provisional && round < options.robust_rounds &&
                                                observations[i].provisional);
      const bool same_kind = block_without_depth[i] == result.depth_dropped[i];
      if (wanted == (blocks[i] != nullptr) && (!wanted || same_kind)) continue;
      if (blocks[i] != nullptr) {
        problem.RemoveResidualBlock(blocks[i]);
        blocks[i] = nullptr;
        if (!wanted) continue;
      }
      const KeypointObservation keypoint = result.depth_dropped[i]
                                               ? WithoutDepth(observations[i].keypoint)
                                               : observations[i].keypoint;
      blocks[i] = problem.AddResidualBlock(
          NewPoseOnlyReprojectionCost(camera, bf, keypoint, observations[i].point_in_world),
          losses.For(keypoint.IsStereo()), pose.data());
      block_without_depth[i] = result.depth_dropped[i];
    }
    if (problem.NumResidualBlocks() - prior_blocks < 3) break;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);

    // Re-classify every observation (including earlier outliers) against the new pose.
    const Rigid3d cam_from_world = FromPoseBlock(pose.data());
    for (size_t i = 0; i < observations.size(); ++i) {
      chi2[i] = ReprojectionChi2(camera, bf, observations[i].keypoint,
                                 cam_from_world * observations[i].point_in_world);
    }
    if (round == 0 && options.min_gate_scale < 1.0) {
      result.gate_scale = MeasuredGateScale(observations, chi2, options);
      if (result.gate_scale < 1.0 && round + 1 < options.robust_rounds) {
        losses.Rescale(options.chi2_mono * result.gate_scale,
                       options.chi2_stereo * result.gate_scale);
      }
    }
    result.nominal_inlier.resize(observations.size());
    for (size_t i = 0; i < observations.size(); ++i) {
      const PoseObservation& obs = observations[i];
      const double factor =
          hold_back_provisional && obs.provisional ? options.provisional_gate_factor : 1.0;
      const double gate = NominalGate(obs, options) * factor;
      result.nominal_inlier[i] = chi2[i] <= gate;
      result.inlier[i] = chi2[i] <= gate * result.gate_scale;
      result.depth_dropped[i] = false;
      // Only where the third residual is the depth's own (disparity form): ORB-SLAM2's u_r
      // residual also carries the pixel's error.
      if (options.depth_fallback && !result.inlier[i] && obs.keypoint.IsStereo() &&
          obs.keypoint.disparity_information > 0.0) {
        // The pixel alone, against the 2-dof gate (scaled and, if provisional, narrowed alike).
        const double pixel_chi2 = ReprojectionChi2(camera, bf, WithoutDepth(obs.keypoint),
                                                   cam_from_world * obs.point_in_world);
        const double pixel_gate = options.chi2_mono * factor;
        if (pixel_chi2 <= pixel_gate * result.gate_scale) {
          result.inlier[i] = true;
          result.nominal_inlier[i] = pixel_chi2 <= pixel_gate;
          result.depth_dropped[i] = true;
        }
      }
    }
  }
  result.cam_from_world = FromPoseBlock(pose.data());
  result.num_inliers = 0;
  for (bool b : result.inlier) result.num_inliers += b ? 1 : 0;
  return result;
}

std::optional<Rigid3d> RefinePoseLeastSquares(const PinholeCamera& camera,
                                              std::vector<Eigen::Vector3d> points_in_world,
                                              const std::vector<Eigen::Vector2d>& pixels,
                                              const Rigid3d& initial_cam_from_world,
                                              int max_iterations) {
  CHECK_EQ(points_in_world.size(), pixels.size()) << "one pixel per point";
  CHECK_GE(max_iterations, 1);
  if (points_in_world.size() < 3) return std::nullopt;
  std::vector<KeypointObservation> observations(pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) observations[i].uv = pixels[i];
  PoseBlock pose = ToPoseBlock(initial_cam_from_world);
  ceres::Problem problem;  // owns the manifold and the cost
  problem.AddParameterBlock(pose.data(), kPoseBlockSize, NewPoseManifold());
  problem.AddResidualBlock(
      NewPoseOnlyBatchCost(camera, 0.0, std::move(observations), std::move(points_in_world)),
      nullptr, pose.data());
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = max_iterations;
  // Ceres' default tolerances end a refit once it has converged: the pose then differs by ~1e-6
  // of its size from where the remaining iterations would take it, far below the 0.1 px at which
  // the FAST filter compares fits. (Running all iterations cost the ego-motion a third more
  // instructions and changed no FAST result: session 51, docs/results.md.)
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return std::nullopt;
  const Rigid3d result = FromPoseBlock(pose.data());
  if (!result.translation.allFinite() || !result.rotation.coeffs().allFinite()) return std::nullopt;
  return result;
}

}  // namespace dynorb
