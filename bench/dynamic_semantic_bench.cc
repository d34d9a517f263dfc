// Semantic mode: ms per inference of each detector (OpenCV DNN, CPU) on the real TUM frame,
// plus the box -> depth-mask refinement and its 8 px elliptic dilation. Needs the models in
// ../shared/models (skipped otherwise).
#include <filesystem>

#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench_util.h"
#include "dynorb/dynamic/detector_dnn.h"
#include "dynorb/dynamic/mask_refine.h"
#include "dynorb/dynamic/morphology.h"
#include "dynorb/dynamic/semantic_filter.h"

namespace dynorb {
namespace {

const std::string kShared = std::string(DYNORB_SOURCE_DIR) + "/../shared";
const std::string kFrame = kShared + "/data/tum/rgbd_dataset_freiburg3_walking_xyz_frame0";

// `process_cpu_ms`: CPU time of the whole process per call (ProcessCpuTimer).
// `opencv_threads` > 0: OpenCV limited to that many threads for the benchmark (CvThreads).
// `dynamic_classes`: only the semantic mode's default classes, as `dynorb run` asks for them
// (darknet heads cut to them).
void BM_Detector(benchmark::State& state, const std::string& model, cv::Size input = {},
                 int opencv_threads = 0, bool dynamic_classes = false) {
  const cv::Mat bgr = cv::imread(kFrame + "/rgb/1341846313.592026.png");
  if (bgr.empty() || !std::filesystem::is_directory(kShared + "/models/" + model)) {
    state.SkipWithError("shared models/data not found");
    return;
  }
  DetectorOptions options;
  options.model = model;
  options.models_dir = kShared + "/models";
  options.input_width = input.width;
  options.input_height = input.height;
  if (dynamic_classes) {
    SemanticOptions semantic;
    semantic.detector = options;
    options = SemanticDetectorOptions(semantic);
  }
  DnnDetector detector(options);
  const CvThreads threads(opencv_threads);
  double inference_ms = 0.0;
  size_t found = 0;
  const ProcessCpuTimer cpu;
  for (auto _ : state) {
    found = detector.Detect(bgr).size();
    inference_ms += detector.last_timing().inference_ms;
  }
  const double cpu_ms = cpu.ElapsedMs();
  const double calls = static_cast<double>(state.iterations());
  state.counters["inference_ms"] = inference_ms / calls;
  state.counters["process_cpu_ms"] = cpu_ms / calls;
  state.counters["detections"] = static_cast<double>(found);
}
BENCHMARK_CAPTURE(BM_Detector, yolo_fastest_1_1, std::string("yolo_fastest_1.1"))->Unit(benchmark::kMillisecond);
// The same on one OpenCV thread: on 2 cores the second thread buys little speed for much CPU
// (session 36, this benchmark: 12.8 ms wall / 24.1 ms CPU per call with 2 threads, 17.6 / 17.6
// with 1).
BENCHMARK_CAPTURE(BM_Detector, yolo_fastest_1_1_one_thread, std::string("yolo_fastest_1.1"),
                  cv::Size(), 1)
    ->Unit(benchmark::kMillisecond);
// As `dynorb run --mode semantic` runs it: heads cut to the 16 default dynamic classes.
BENCHMARK_CAPTURE(BM_Detector, yolo_fastest_1_1_dynamic_classes, std::string("yolo_fastest_1.1"),
                  cv::Size(), 0, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Detector, yolo_fastest_1_1_dynamic_classes_one_thread,
                  std::string("yolo_fastest_1.1"), cv::Size(), 1, true)
    ->Unit(benchmark::kMillisecond);
// The same network on a 320 x 256 input: the 4:3 frame stretched less, 20 % fewer pixels.
BENCHMARK_CAPTURE(BM_Detector, yolo_fastest_1_1_320x256, std::string("yolo_fastest_1.1"),
                  cv::Size(320, 256))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Detector, yolo_fastest_1_1_xl, std::string("yolo_fastest_1.1_xl"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Detector, yolo_fastest_1_1_body, std::string("yolo_fastest_1.1_body"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Detector, yolox_nano, std::string("yolox_nano"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Detector, fastestdet, std::string("fastestdet"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Detector, nanodet_m_320, std::string("nanodet_m_320"))->Unit(benchmark::kMillisecond);

void BM_DepthRefine(benchmark::State& state) {
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(4.f));
  depth(cv::Rect(250, 100, 120, 380)) = 1.5f;
  DepthRefineOptions options;
  cv::Mat mask(480, 640, CV_8U);
  for (auto _ : state) {
    mask.setTo(0);
    benchmark::DoNotOptimize(AddRefinedBoxMask({200, 80, 220, 400}, depth, options, 0.f, &mask));
  }
}
BENCHMARK(BM_DepthRefine)->Unit(benchmark::kMicrosecond);

// The 8 px elliptic dilation of a person-sized mask canvas: cv::dilate (one pass per element
// pixel) against DilateEllipse (one per element row and half-width; same pixels).
void BM_EllipseDilation(benchmark::State& state) {
  cv::Mat canvas = cv::Mat::zeros(416, 236, CV_8U);
  canvas(cv::Rect(8, 8, 220, 400)).setTo(255);
  canvas(cv::Rect(60, 100, 90, 250)).setTo(0);
  const cv::Mat element = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(17, 17));
  cv::Mat out;
  for (auto _ : state) {
    if (state.range(0) == 0) {
      cv::dilate(canvas, out, element);
    } else {
      DilateEllipse(canvas, 8, &out);
    }
    benchmark::DoNotOptimize(out.data);
  }
}
BENCHMARK(BM_EllipseDilation)->Arg(0)->Arg(1)->ArgNames({"rows"})->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace dynorb
