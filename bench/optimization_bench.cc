// Benchmarks of the local bundle adjustment (dynorb/optimization): a problem the size of the
// walking sequences' local windows (~20 keyframes, 8 of them fixed, ~1700 points, ~5000
// observations, 70 % with depth), solved as the local mapper solves it (5 robust + 10 L2 LM
// iterations). Arg: number of points. And a global BA of 30-120 keyframes, dense or sparse.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "dynorb/optimization/bundle_adjuster.h"
#include "dynorb/optimization/pose_optimizer.h"
#include "dynorb/optimization/test_scene.h"

namespace dynorb {
namespace {

struct BaScene {
  PinholeCamera camera{525.0, 525.0, 319.5, 239.5};
  double bf = 40.0;
  std::vector<BaKeyframe> keyframes;
  std::vector<Eigen::Vector3d> points;
  std::vector<BaObservation> observations;
};

// Keyframe k's true pose: keyframes 5 cm apart along x, turning 1 degree each.
Rigid3d TruthCamFromWorld(int k) {
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.0175 * k, Eigen::Vector3d::UnitY())),
                 Eigen::Vector3d(0.05 * k, 0.0, 0.0))
      .Inverse();
}

// `local_points`: each point placed in front of the first keyframe that sees it (a long path,
// where the world-frame box would fall behind the later keyframes).
BaScene MakeScene(int num_points, int num_keyframes = 20, int num_fixed = 8, bool local_points = false) {
  BaScene s;
  std::mt19937_64 rng(5);
  for (int k = 0; k < num_keyframes; ++k) {
    const Rigid3d truth = TruthCamFromWorld(k);
    BaKeyframe kf;
    kf.fixed = k < num_fixed;
    kf.cam_from_world = kf.fixed ? truth : testing::Perturb(truth, 0.005, 0.01, rng);
    s.keyframes.push_back(kf);
  }
  const std::vector<Eigen::Vector3d> truth_points = testing::RandomPointsInWorld(num_points, rng);
  std::uniform_int_distribution<int> pick(0, num_keyframes - (local_points ? 3 : 1));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> jitter(0.0, 0.02);
  for (int i = 0; i < num_points; ++i) {
    const int first = pick(rng);
    const Eigen::Vector3d point =
        local_points ? TruthCamFromWorld(first).Inverse() * truth_points[i] : truth_points[i];
    s.points.push_back(point + Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng)));
    for (int j = 0; j < 3; ++j) {  // Three consecutive keyframes see each point.
      const int k = (first + j) % num_keyframes;  // local_points: first <= num_keyframes - 3
      BaObservation obs;
      obs.keyframe_index = k;
      obs.landmark_index = i;
      obs.keypoint = testing::Observe(s.camera, s.bf, TruthCamFromWorld(k), point, unit(rng) < 0.7,
                                      1.0, rng);
      s.observations.push_back(obs);
    }
  }
  return s;
}

void BM_LocalBundleAdjustment(benchmark::State& state) {
  const BaScene scene = MakeScene(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    const BundleAdjusterResult r =
        RunBundleAdjustment(scene.camera, scene.bf, scene.keyframes, scene.points, scene.observations);
    benchmark::DoNotOptimize(r.final_cost);
  }
  state.counters["observations"] = static_cast<double>(scene.observations.size());
}
BENCHMARK(BM_LocalBundleAdjustment)->Arg(600)->Arg(1700)->Unit(benchmark::kMillisecond);

// A global BA after a loop (loop_closing/global_bundle_adjustment.h): every keyframe free but the
// first, 150 points per keyframe, the local BA's 5 robust + 10 L2 iterations. Args: keyframes,
// and 1 for a dense / 0 for a sparse Schur factorisation (BundleAdjusterOptions::
// dense_max_keyframes, 60). Session 40: 298 / 303 ms at 30 keyframes, 802 / 720 at 60, 1996 /
// 1848 at 120 (dense / sparse): most of the time is residual and Jacobian evaluation.
void BM_GlobalBundleAdjustment(benchmark::State& state) {
  const int keyframes = static_cast<int>(state.range(0));
  const BaScene scene = MakeScene(150 * keyframes, keyframes, 1, true);
  BundleAdjusterOptions options;
  options.dense_max_keyframes = state.range(1) ? keyframes : 0;
  for (auto _ : state) {
    const BundleAdjusterResult r = RunBundleAdjustment(scene.camera, scene.bf, scene.keyframes,
                                                       scene.points, scene.observations, options);
    benchmark::DoNotOptimize(r.final_cost);
  }
  state.counters["observations"] = static_cast<double>(scene.observations.size());
}
BENCHMARK(BM_GlobalBundleAdjustment)
    ->ArgsProduct({{30, 60, 120}, {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);

// One frame's pose solve as the tracker runs it (4 rounds of up to 10 LM iterations): `n`
// landmarks 1-5 m away, 70 % with depth, 1 px noise, 10 % gross outliers, start 2 cm / 1 degree off.
void BM_PoseOptimization(benchmark::State& state) {
  std::mt19937_64 rng(9);
  const PinholeCamera camera{525.0, 525.0, 319.5, 239.5};
  const double bf = 40.0;
  const Rigid3d truth;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gross(0.0, 30.0);
  std::vector<PoseObservation> observations;
  for (const Eigen::Vector3d& p : testing::RandomPointsInWorld(static_cast<int>(state.range(0)), rng)) {
    PoseObservation obs;
    obs.point_in_world = p;
    obs.keypoint = testing::Observe(camera, bf, truth, p, unit(rng) < 0.7, 1.0, rng);
    if (unit(rng) < 0.1) obs.keypoint.uv += Eigen::Vector2d(gross(rng), gross(rng));
    observations.push_back(obs);
  }
  const Rigid3d start = testing::Perturb(truth, 0.0175, 0.02, rng);
  for (auto _ : state) {
    const PoseOptimizerResult r = OptimizePose(camera, bf, observations, start);
    benchmark::DoNotOptimize(r.num_inliers);
  }
}
BENCHMARK(BM_PoseOptimization)->Arg(350)->Unit(benchmark::kMicrosecond);

// One refit of the FAST filter's ego-motion: `n` points with 0.15 px noise, start 0.2 degrees /
// 4 mm off, at most 5 LM iterations, plain least squares. RefinePoseLeastSquares (Ceres, one
// residual block) against what the ego-motion used before session 15 (cv::solvePnPRefineLM).
struct RefitScene {
  PinholeCamera camera{535.4, 539.2, 320.1, 247.6};
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  Rigid3d start;
  explicit RefitScene(int n) {
    std::mt19937_64 rng(15);
    const Rigid3d truth = testing::Perturb(Rigid3d(), 0.01, 0.02, rng);
    points = testing::RandomPointsInWorld(n, rng);
    for (const Eigen::Vector3d& p : points) {
      pixels.push_back(testing::Observe(camera, 0.0, truth, p, false, 0.15, rng).uv);
    }
    start = testing::Perturb(truth, 0.0035, 0.004, rng);
  }
};
void BM_EgoRefit_Ceres(benchmark::State& state) {
  const RefitScene scene(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        RefinePoseLeastSquares(scene.camera, scene.points, scene.pixels, scene.start, 5));
  }
}
BENCHMARK(BM_EgoRefit_Ceres)->Arg(150)->Unit(benchmark::kMicrosecond);
void BM_EgoRefit_OpenCv(benchmark::State& state) {
  const RefitScene scene(static_cast<int>(state.range(0)));
  std::vector<cv::Point3f> object;
  std::vector<cv::Point2f> image;
  for (size_t i = 0; i < scene.points.size(); ++i) {
    object.emplace_back(scene.points[i].x(), scene.points[i].y(), scene.points[i].z());
    image.emplace_back(scene.pixels[i].x(), scene.pixels[i].y());
  }
  const cv::Mat k = (cv::Mat_<double>(3, 3) << scene.camera.fx, 0, scene.camera.cx, 0,
                     scene.camera.fy, scene.camera.cy, 0, 0, 1);
  cv::Mat r, rvec0;
  cv::eigen2cv(Eigen::Matrix3d(scene.start.rotation.toRotationMatrix()), r);
  cv::Rodrigues(r, rvec0);
  const cv::Mat tvec0 = (cv::Mat_<double>(3, 1) << scene.start.translation.x(),
                         scene.start.translation.y(), scene.start.translation.z());
  for (auto _ : state) {
    cv::Mat rvec = rvec0.clone(), tvec = tvec0.clone();
    cv::solvePnPRefineLM(
        object, image, k, cv::noArray(), rvec, tvec,
        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 5, 1e-8));
    benchmark::DoNotOptimize(tvec.data);
  }
}
BENCHMARK(BM_EgoRefit_OpenCv)->Arg(150)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace dynorb
