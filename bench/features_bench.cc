// ORB extraction and matching speed on a 640×480 frame (target: Detect + Describe well under
// ~15 ms on one core so tracking keeps ≥ 30 Hz). Image: the real TUM fr3 frame in ../shared if
// present, else OpenCV's graf1.png, else a synthetic texture (the label says which).
// The *_1thread variants pin OpenCV to one thread (CvThreads, bench_util.h) and restore it after.
#include <benchmark/benchmark.h>

#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "bench_util.h"
#include "dynorb/features/orb_extractor.h"
#include "dynorb/features/orb_matcher.h"
#include "dynorb/features/synthetic_texture.h"

namespace dynorb {
namespace {

struct BenchImage {
  cv::Mat gray;
  std::string label;
};

const BenchImage& Frame() {
  static const BenchImage frame = [] {
    const std::string candidates[] = {
        std::string(DYNORB_SOURCE_DIR) +
            "/../shared/data/tum/rgbd_dataset_freiburg3_walking_xyz_frame0/rgb/"
            "1341846313.592026.png",
        "/usr/share/doc/opencv-doc/examples/data/graf1.png"};
    for (const std::string& path : candidates) {
      if (!std::ifstream(path).good()) continue;
      cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
      if (image.empty()) continue;
      if (image.size() != cv::Size(640, 480))
        cv::resize(image, image, cv::Size(640, 480), 0, 0, cv::INTER_AREA);
      return BenchImage{image, path.substr(path.find_last_of('/') + 1)};
    }
    return BenchImage{MakeSyntheticTexture(cv::Size(640, 480), 1), "synthetic"};
  }();
  return frame;
}

void BM_OrbDetect(benchmark::State& state) {
  const CvThreads threads(state.range(0) == 1 ? 1 : 0);
  const OrbExtractor extractor;
  const cv::Mat& image = Frame().gray;
  int n = 0;
  for (auto _ : state) {
    KeypointSet set = extractor.Detect(image);
    n = set.size();
    benchmark::DoNotOptimize(set);
  }
  state.SetLabel(Frame().label + " keypoints=" + std::to_string(n));
}
BENCHMARK(BM_OrbDetect)->Arg(1)->Arg(0)->ArgName("one_thread")->Unit(benchmark::kMillisecond);

void BM_OrbDescribe(benchmark::State& state) {
  const CvThreads threads(state.range(0) == 1 ? 1 : 0);
  const OrbExtractor extractor;
  const KeypointSet set = extractor.Detect(Frame().gray);
  for (auto _ : state) benchmark::DoNotOptimize(extractor.Describe(set));
  state.SetLabel(Frame().label);
}
BENCHMARK(BM_OrbDescribe)->Arg(1)->ArgName("one_thread")->Unit(benchmark::kMillisecond);

void BM_OrbDetectAndDescribe(benchmark::State& state) {
  const CvThreads threads(state.range(0) == 1 ? 1 : 0);
  const OrbExtractor extractor;
  const cv::Mat& image = Frame().gray;
  for (auto _ : state) benchmark::DoNotOptimize(extractor.DetectAndDescribe(image));
  state.SetLabel(Frame().label);
}
BENCHMARK(BM_OrbDetectAndDescribe)
    ->Arg(1)
    ->Arg(0)
    ->ArgName("one_thread")
    ->Unit(benchmark::kMillisecond);

// OpenCV's ORB with ORB-SLAM-like parameters, for comparison (Harris ranking, no quadtree).
void BM_CvOrbDetectAndCompute(benchmark::State& state) {
  const CvThreads threads(state.range(0) == 1 ? 1 : 0);
  cv::Ptr<cv::ORB> orb = cv::ORB::create(1000, 1.2f, 8, 19, 0, 2, cv::ORB::HARRIS_SCORE, 31, 20);
  const cv::Mat& image = Frame().gray;
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  for (auto _ : state) {
    orb->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
    benchmark::DoNotOptimize(descriptors);
  }
  state.SetLabel(Frame().label + " keypoints=" + std::to_string(keypoints.size()));
}
BENCHMARK(BM_CvOrbDetectAndCompute)
    ->Arg(1)
    ->Arg(0)
    ->ArgName("one_thread")
    ->Unit(benchmark::kMillisecond);

void BM_MatchBruteForce1000x1000(benchmark::State& state) {
  cv::Mat a(1000, kBriefBytes, CV_8UC1), b(1000, kBriefBytes, CV_8UC1);
  cv::RNG rng(1);
  rng.fill(a, cv::RNG::UNIFORM, 0, 256);
  rng.fill(b, cv::RNG::UNIFORM, 0, 256);
  for (auto _ : state) benchmark::DoNotOptimize(MatchBruteForce(a, b));
}
BENCHMARK(BM_MatchBruteForce1000x1000)->Unit(benchmark::kMillisecond);

void BM_KeypointGridBuildAndQuery(benchmark::State& state) {
  const KeypointSet set = OrbExtractor().Detect(Frame().gray);
  std::vector<int> found;
  for (auto _ : state) {
    const KeypointGrid grid(set.keypoints, Frame().gray.size());
    for (const cv::KeyPoint& kp : set.keypoints) {
      grid.FindInRadius(kp.pt.x + 3.f, kp.pt.y - 2.f, 15.f, &found, kp.octave - 1, kp.octave + 1);
      benchmark::DoNotOptimize(found.data());
    }
  }
  state.SetLabel(std::to_string(set.size()) + " queries of r=15 px");
}
BENCHMARK(BM_KeypointGridBuildAndQuery)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace dynorb
