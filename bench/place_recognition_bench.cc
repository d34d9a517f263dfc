// Place recognition costs: the bag of words of one frame's 1000 ORB descriptors with the built-in
// vocabulary (done for every keyframe and every lost frame), and a pose-graph solve of the size
// loop closing meets (a 200-keyframe ring with odometry, strong covisibility and one loop edge).
// Descriptors: dynorb's extractor on OpenCV's graf1.png (opencv-doc) if present, else random.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include <opencv2/imgcodecs.hpp>

#include "dynorb/features/orb_extractor.h"
#include "dynorb/optimization/pose_graph.h"
#include "dynorb/place_recognition/builtin_vocabulary.h"

namespace dynorb {
namespace {

cv::Mat Descriptors() {
  const cv::Mat image =
      cv::imread("/usr/share/doc/opencv-doc/examples/data/graf1.png", cv::IMREAD_GRAYSCALE);
  if (!image.empty()) return OrbExtractor().DetectAndDescribe(image).descriptors;
  cv::Mat random(1000, 32, CV_8UC1);
  cv::randu(random, 0, 256);
  return random;
}

void BM_BowTransform(benchmark::State& state) {
  const auto vocabulary = BuiltInVocabulary();
  const cv::Mat descriptors = Descriptors();
  for (auto _ : state) benchmark::DoNotOptimize(vocabulary->Transform(descriptors));
  state.counters["descriptors"] = descriptors.rows;
}
BENCHMARK(BM_BowTransform)->Unit(benchmark::kMicrosecond);

void BM_PoseGraph200(benchmark::State& state) {
  const int n = 200;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.002);
  const auto truth = [&](int i) {
    const double a = 2.0 * M_PI * i / n;
    return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY())),
                   Eigen::Vector3d(3.0 * std::cos(a), 0.0, 3.0 * std::sin(a)));
  };
  std::vector<PoseGraphEdge> edges;
  for (int i = 0; i < n; ++i) {
    for (int d = 1; d <= 3 && i + d < n; ++d) {
      const Rigid3d error(
          Eigen::Quaterniond(Eigen::AngleAxisd(noise(rng), Eigen::Vector3d::UnitY())),
          Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
      edges.push_back({static_cast<uint64_t>(i), static_cast<uint64_t>(i + d),
                       error * truth(i + d) * truth(i).Inverse()});
    }
  }
  edges.push_back({static_cast<uint64_t>(n - 1), 0, truth(0) * truth(n - 1).Inverse()});
  for (auto _ : state) {
    std::map<uint64_t, Rigid3d> poses;
    for (int i = 0; i < n; ++i) poses[i] = truth(i);
    benchmark::DoNotOptimize(OptimizePoseGraph(&poses, edges, {0}));
  }
  state.counters["edges"] = static_cast<double>(edges.size());
}
BENCHMARK(BM_PoseGraph200)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace dynorb
