#include "dynorb/optimization/bundle_adjuster.h"

#include <cmath>

#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "dynorb/core/error.h"
#include "dynorb/optimization/pose_block.h"

namespace dynorb {

void BundleAdjusterOptions::Validate() const {
  if (first_iterations < 1 || second_iterations < 0 || chi2_mono <= 0.0 || chi2_stereo <= 0.0) {
    throw InputError("bundle adjuster: iterations must be >= 1 and chi2 gates > 0");
  }
}

namespace {

double Solve(ceres::Problem* problem, int iterations, double* initial_cost) {
  ceres::Solver::Options options;
  // Points are eliminated (Schur); the reduced camera system of a local window (<= a few dozen
  // poses) is small, so a dense factorisation beats a sparse one.
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.max_num_iterations = iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem, &summary);
  if (initial_cost != nullptr) *initial_cost = summary.initial_cost;
  return summary.final_cost;
}

}  // namespace

BundleAdjusterResult RunBundleAdjustment(const PinholeCamera& camera, double bf,
                                         const std::vector<BaKeyframe>& keyframes,
                                         const std::vector<Eigen::Vector3d>& points_in_world,
                                         const std::vector<BaObservation>& observations,
                                         const BundleAdjusterOptions& options) {
  BundleAdjusterResult result;
  std::vector<PoseBlock> poses;
  poses.reserve(keyframes.size());
  for (const BaKeyframe& kf : keyframes) poses.push_back(ToPoseBlock(kf.cam_from_world));
  std::vector<Eigen::Vector3d> points = points_in_world;
  result.observation_inlier.assign(observations.size(), true);

  for (int stage = 0; stage < 2; ++stage) {
    const int iterations = stage == 0 ? options.first_iterations : options.second_iterations;
    if (iterations == 0) break;
    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    int residuals = 0;
    for (size_t i = 0; i < observations.size(); ++i) {
      if (!result.observation_inlier[i]) continue;
      const BaObservation& obs = observations[i];
      double* pose = poses.at(obs.keyframe_index).data();
      double* point = points.at(obs.landmark_index).data();
      if (!problem.HasParameterBlock(pose)) {
        problem.AddParameterBlock(pose, kPoseBlockSize, NewPoseManifold());
        if (keyframes[obs.keyframe_index].fixed) problem.SetParameterBlockConstant(pose);
      }
      const double gate = obs.keypoint.IsStereo() ? options.chi2_stereo : options.chi2_mono;
      ceres::LossFunction* loss = stage == 0 ? new ceres::HuberLoss(std::sqrt(gate)) : nullptr;
      problem.AddResidualBlock(NewReprojectionCost(camera, bf, obs.keypoint), loss, pose, point);
      ++residuals;
    }
    if (residuals == 0) break;
    double initial = 0.0;
    result.final_cost = Solve(&problem, iterations, &initial);
    if (stage == 0) result.initial_cost = initial;
    result.converged = true;

    for (size_t i = 0; i < observations.size(); ++i) {
      const BaObservation& obs = observations[i];
      const double gate = obs.keypoint.IsStereo() ? options.chi2_stereo : options.chi2_mono;
      const Eigen::Vector3d point_in_cam = FromPoseBlock(poses[obs.keyframe_index].data()) * points[obs.landmark_index];
      result.observation_inlier[i] = ReprojectionChi2(camera, bf, obs.keypoint, point_in_cam) <= gate;
    }
  }
  for (const PoseBlock& p : poses) result.cam_from_world.push_back(FromPoseBlock(p.data()));
  result.points_in_world = std::move(points);
  return result;
}

}  // namespace dynorb
