#include "dynorb/optimization/bundle_adjuster.h"

#include <cmath>

#include <ceres/iteration_callback.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "dynorb/core/error.h"
#include "dynorb/optimization/pose_block.h"
#include "dynorb/optimization/robust_problem.h"

namespace dynorb {

void BundleAdjusterOptions::Validate() const {
  if (first_iterations < 1 || second_iterations < 0 || chi2_mono <= 0.0 || chi2_stereo <= 0.0 ||
      dense_max_keyframes < 0) {
    throw InputError(
        "bundle adjuster: iterations must be >= 1, chi2 gates > 0, dense_max_keyframes >= 0");
  }
}

namespace {

class StopCallback : public ceres::IterationCallback {
 public:
  explicit StopCallback(const std::atomic<bool>* stop) : stop_(stop) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return stop_->load() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }

 private:
  const std::atomic<bool>* stop_;
};

// Returns false if options.stop ended the solve; `usable`: Ceres says the parameters hold a
// solution (not a failed start, e.g. a linear solver the Ceres build lacks).
bool Solve(ceres::Problem* problem, int iterations, bool dense, const std::atomic<bool>* stop,
           double* initial_cost, double* final_cost, bool* usable) {
  ceres::Solver::Options options;
  // Points are eliminated (Schur); the reduced camera system of a local window (<= a few dozen
  // poses) is small, so a dense factorisation beats a sparse one.
  options.linear_solver_type = dense ? ceres::DENSE_SCHUR : ceres::SPARSE_SCHUR;
  options.max_num_iterations = iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  StopCallback callback(stop);
  if (stop != nullptr) options.callbacks.push_back(&callback);
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem, &summary);
  if (initial_cost != nullptr) *initial_cost = summary.initial_cost;
  *final_cost = summary.final_cost;
  *usable = summary.IsSolutionUsable();
  return !(stop != nullptr && stop->load());
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

  // One problem for both stages (building it costs as much as an LM iteration): the Huber
  // kernels sit behind wrappers that are switched to plain L2 for the second stage, and the
  // first stage's outliers are removed from the problem instead of rebuilding it.
  StagedLosses losses(options.chi2_mono, options.chi2_stereo);
  ceres::Problem problem(StagedProblemOptions());
  std::vector<ceres::ResidualBlockId> blocks(observations.size(), nullptr);
  for (size_t i = 0; i < observations.size(); ++i) {
    const BaObservation& obs = observations[i];
    double* pose = poses.at(obs.keyframe_index).data();
    double* point = points.at(obs.landmark_index).data();
    if (!problem.HasParameterBlock(pose)) {
      problem.AddParameterBlock(pose, kPoseBlockSize, NewPoseManifold());
      if (keyframes[obs.keyframe_index].fixed) problem.SetParameterBlockConstant(pose);
    }
    blocks[i] = problem.AddResidualBlock(NewReprojectionCost(camera, bf, obs.keypoint),
                                         losses.For(obs.keypoint.IsStereo()), pose, point);
  }

  int free_keyframes = 0;
  for (const BaKeyframe& kf : keyframes) free_keyframes += kf.fixed ? 0 : 1;
  for (int stage = 0; stage < 2 && !observations.empty(); ++stage) {
    const int iterations = stage == 0 ? options.first_iterations : options.second_iterations;
    if (iterations == 0) break;
    if (stage == 1) {
      losses.SwitchToL2();
      for (size_t i = 0; i < observations.size(); ++i) {
        if (result.observation_inlier[i] || blocks[i] == nullptr) continue;
        problem.RemoveResidualBlock(blocks[i]);
        blocks[i] = nullptr;
      }
    }
    if (problem.NumResidualBlocks() == 0) break;
    double initial = 0.0;
    bool usable = false;
    const bool finished = Solve(&problem, iterations, free_keyframes <= options.dense_max_keyframes,
                                options.stop, &initial, &result.final_cost, &usable);
    if (stage == 0) result.initial_cost = initial;
    if (!finished) {
      result.stopped = true;
      break;
    }
    if (!usable) {
      result.failed = true;
      break;
    }
    result.converged = stage == 0 || result.converged;

    for (size_t i = 0; i < observations.size(); ++i) {
      const BaObservation& obs = observations[i];
      const double gate = obs.keypoint.IsStereo() ? options.chi2_stereo : options.chi2_mono;
      const Eigen::Vector3d point_in_cam = FromPoseBlock(poses[obs.keyframe_index].data()) * points[obs.landmark_index];
      // An observation removed after the first stage stays out (ORB-SLAM2 excludes it too).
      result.observation_inlier[i] =
          blocks[i] != nullptr && ReprojectionChi2(camera, bf, obs.keypoint, point_in_cam) <= gate;
    }
  }
  for (const PoseBlock& p : poses) result.cam_from_world.push_back(FromPoseBlock(p.data()));
  result.points_in_world = std::move(points);
  return result;
}

}  // namespace dynorb
