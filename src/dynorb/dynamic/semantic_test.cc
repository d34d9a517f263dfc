// Semantic mode: real detectors on real images (hand-checked person regions), the deterministic
// schedule and mask carrying, FileMaskProvider, bad input (box -> mask refinement:
// mask_refine_test.cc).
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "dynorb/core/error.h"
#include "dynorb/dynamic/detector_dnn.h"
#include "dynorb/dynamic/mask_file.h"
#include "dynorb/dynamic/semantic_filter.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;

const std::string kShared = DYNORB_SHARED_DIR;
const std::string kModels = kShared + "/models";
const std::string kTumFrame = kShared + "/data/tum/rgbd_dataset_freiburg3_walking_xyz_frame0";

// Best IoU of a person detection with `region`.
float BestPersonIou(const DnnDetector& detector, const std::vector<Detection>& detections, const cv::Rect2f& region) {
  float best = 0.f;
  for (const Detection& d : detections) {
    if (detector.class_names()[d.class_id] == "person") best = std::max(best, BoxIou(d.box, region));
  }
  return best;
}

TEST(SemanticDetector, EveryModelFindsThePeopleInRealImages) {
  if (!fs::is_directory(kModels) || !fs::is_directory(kTumFrame)) GTEST_SKIP() << "no shared models/data at " << kShared;
  const cv::Mat photo = cv::imread(kShared + "/data/images/person_dog_horse.jpg");
  cv::Mat street = cv::imread(kShared + "/data/images/street.jpg");
  cv::resize(street, street, {640, 480});
  const cv::Mat tum = cv::imread(kTumFrame + "/rgb/1341846313.592026.png");
  ASSERT_FALSE(photo.empty() || street.empty() || tum.empty());
  for (const ModelSpec& spec : SupportedModels()) {
    SCOPED_TRACE(spec.name);
    DetectorOptions options;
    options.model = spec.name;
    options.models_dir = kModels;
    DnnDetector detector(options);
    // Hand-checked person boxes (x, y, w, h).
    EXPECT_GT(BestPersonIou(detector, detector.Detect(photo), {186, 98, 88, 275}), 0.6f);
    EXPECT_GT(BestPersonIou(detector, detector.Detect(street), {470, 235, 78, 192}), 0.6f);
    const auto people = detector.Detect(tum);
    EXPECT_GT(BestPersonIou(detector, people, {45, 130, 200, 340}), 0.6f) << "seated person (left)";
    EXPECT_GT(BestPersonIou(detector, people, {460, 5, 178, 470}), 0.6f) << "standing person (right)";
  }
}

// A score threshold below OpenCV's darknet floor (0.2) takes effect, whole or pruned; the
// detections above the default threshold stay the same (NMS is greedy by score).
TEST(SemanticDetector, DarknetScoreThresholdBelowOpenCvsFloorTakesEffect) {
  if (!fs::is_directory(kModels) || !fs::is_directory(kTumFrame))
    GTEST_SKIP() << "no shared models/data at " << kShared;
  const cv::Mat tum = cv::imread(kTumFrame + "/rgb/1341846313.592026.png");
  ASSERT_FALSE(tum.empty());
  for (const bool whole : {true, false}) {
    SCOPED_TRACE(whole ? "all classes" : "pruned to person, chair");
    DetectorOptions options;
    options.model = "yolo_fastest_1.1";
    options.models_dir = kModels;
    if (!whole) options.classes = {"person", "chair"};
    const std::vector<Detection> usual = DnnDetector(options).Detect(tum);
    options.score_threshold = 0.05;
    const std::vector<Detection> low = DnnDetector(options).Detect(tum);
    EXPECT_TRUE(
        std::any_of(low.begin(), low.end(), [](const Detection& d) { return d.score < 0.2f; }));
    std::vector<Detection> above;
    for (const Detection& d : low)
      if (d.score >= 0.3f) above.push_back(d);
    ASSERT_EQ(above.size(), usual.size());
    for (const Detection& d : usual) {
      EXPECT_TRUE(std::any_of(above.begin(), above.end(), [&](const Detection& e) {
        return e.class_id == d.class_id && std::abs(e.score - d.score) < 1e-5f &&
               BoxIou(e.box, d.box) > 0.999f;
      }));
    }
  }
}

void ExpectInputError(const DetectorOptions& options, const std::string& needle) {
  try {
    DnnDetector detector(options);
    FAIL() << "no error for " << needle;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

// Asked for some classes, a darknet model runs with its heads cut to them and finds exactly what
// the whole network finds among those classes (same boxes and scores up to float rounding); an
// ONNX model runs whole and ignores the other classes.
TEST(SemanticDetector, ClassPrunedHeadsFindWhatTheWholeNetworkFinds) {
  if (!fs::is_directory(kModels)) GTEST_SKIP() << "no shared models at " << kShared;
  const cv::Mat photo = cv::imread(kShared + "/data/images/person_dog_horse.jpg");
  const cv::Mat tum = cv::imread(kTumFrame + "/rgb/1341846313.592026.png");
  ASSERT_FALSE(photo.empty() || tum.empty());
  for (const std::string model : {"yolo_fastest_1.1", "yolo_fastest_1.1_xl", "fastestdet"}) {
    SCOPED_TRACE(model);
    DetectorOptions options;
    options.model = model;
    options.models_dir = kModels;
    options.classes = {"person", "dog", "horse", "car"};
    DnnDetector cut(options);
    options.prune_heads = false;
    DnnDetector whole(options);
    EXPECT_EQ(cut.pruned(), model != "fastestdet");
    EXPECT_FALSE(whole.pruned());
    for (const cv::Mat* image : {&photo, &tum}) {
      const auto a = whole.Detect(*image), b = cut.Detect(*image);
      ASSERT_EQ(a.size(), b.size());
      ASSERT_FALSE(a.empty());
      for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(whole.class_names()[a[i].class_id], cut.class_names()[b[i].class_id]);
        EXPECT_NEAR(a[i].score, b[i].score, 1e-4);
        EXPECT_NEAR(a[i].box.x, b[i].box.x, 0.05);
        EXPECT_NEAR(a[i].box.y, b[i].box.y, 0.05);
        EXPECT_NEAR(a[i].box.width, b[i].box.width, 0.05);
        EXPECT_NEAR(a[i].box.height, b[i].box.height, 0.05);
        EXPECT_NE(std::find(options.classes.begin(), options.classes.end(),
                            cut.class_names()[b[i].class_id]),
                  options.classes.end());
      }
    }
  }
  // The single-class body model has nothing to cut; a class it does not have is an error.
  DetectorOptions body;
  body.model = "yolo_fastest_1.1_body";
  body.models_dir = kModels;
  body.classes = {"person", "car"};
  EXPECT_FALSE(DnnDetector(body).pruned());
  body.classes = {"car"};
  ExpectInputError(body, "has none of the classes car");
}

// The darknet models are fully convolutional: on a 320 x 256 input (a 4:3 frame stretched less,
// 20 % fewer pixels) they find the same people; the ONNX models refuse another size.
TEST(SemanticDetector, DarknetModelsTakeAnAspectMatchedInputSize) {
  if (!fs::is_directory(kModels) || !fs::is_directory(kTumFrame))
    GTEST_SKIP() << "no shared models/data at " << kShared;
  const cv::Mat photo = cv::imread(kShared + "/data/images/person_dog_horse.jpg");
  const cv::Mat tum = cv::imread(kTumFrame + "/rgb/1341846313.592026.png");
  ASSERT_FALSE(photo.empty() || tum.empty());
  for (const std::string model :
       {"yolo_fastest_1.1", "yolo_fastest_1.1_xl", "yolo_fastest_1.1_body"}) {
    SCOPED_TRACE(model);
    DetectorOptions options;
    options.model = model;
    options.models_dir = kModels;
    options.input_width = 320;
    options.input_height = 256;
    DnnDetector detector(options);
    EXPECT_EQ(detector.spec().input, cv::Size(320, 256));
    EXPECT_GT(BestPersonIou(detector, detector.Detect(photo), {186, 98, 88, 275}), 0.6f);
    const auto people = detector.Detect(tum);
    EXPECT_GT(BestPersonIou(detector, people, {45, 130, 200, 340}), 0.6f) << "seated person (left)";
    EXPECT_GT(BestPersonIou(detector, people, {460, 5, 178, 470}), 0.6f)
        << "standing person (right)";
  }
}

TEST(SemanticDetector, BadInputSizeIsAnInputError) {
  DetectorOptions options;
  options.input_width = 320;
  options.input_height = 250;  // not a multiple of 32
  EXPECT_THROW(options.Validate(), InputError);
  options.input_height = 0;  // only one of the two
  EXPECT_THROW(options.Validate(), InputError);
  options.input_height = 256;
  EXPECT_NO_THROW(options.Validate());
  options.model = "yolox_nano";  // fixed ONNX input
  EXPECT_THROW(options.Validate(), InputError);
}

TEST(SemanticDetector, RealTumFrameMaskKeepsTheBackgroundInsideTheBox) {
  if (!fs::is_directory(kModels) || !fs::is_directory(kTumFrame)) GTEST_SKIP() << "no shared models/data at " << kShared;
  const cv::Mat bgr = cv::imread(kTumFrame + "/rgb/1341846313.592026.png");
  cv::Mat depth16 = cv::imread(kTumFrame + "/depth/1341846313.592088.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(depth16.type(), CV_16U);
  cv::Mat depth;
  depth16.convertTo(depth, CV_32F, 1.0 / 5000.0);
  SemanticOptions options;
  options.detector.models_dir = kModels;
  DetectorMaskProvider provider(options);
  const DynamicObjects objects = provider.Masks({0, 0.0, &bgr, &depth});
  ASSERT_GE(objects.objects.size(), 2u);
  // Torso of the standing person masked; the monitor behind the seated person's box right edge
  // (inside the box, far behind) is not.
  EXPECT_EQ(objects.mask.at<uint8_t>(200, 560), 255);
  EXPECT_EQ(objects.mask.at<uint8_t>(250, 130), 255);
  const double masked = cv::countNonZero(objects.mask) / static_cast<double>(bgr.total());
  EXPECT_LT(masked, 0.45);
}

// A provider that reports a square at a known place and counts its calls.
class SquareProvider : public MaskProvider {
 public:
  std::string name() const override { return "square"; }
  DynamicObjects Masks(const MaskQuery& query) override {
    calls.push_back(query.frame_id);
    if (log) log->push_back(query.frame_id);
    DynamicObjects out;
    out.mask = cv::Mat::zeros(query.bgr->size(), CV_8U);
    Detection d;
    d.box = cv::Rect2f(static_cast<float>(x0 + speed * query.frame_id), 40.f, 40.f, 40.f);
    d.class_id = 0;
    const RefinedMask r = AddRefinedBoxMask(d.box, *query.depth_m, refine, 0.f, &out.mask);
    out.objects.push_back({d, r.depth_m});
    return out;
  }
  std::vector<FrameId> calls;
  std::shared_ptr<std::vector<FrameId>> log;  // Outlives the provider (owned by the filter).
  int x0 = 30, speed = 3;
  DepthRefineOptions refine;
};

// Textured square moving right over a textured far background.
void MakeFrame(int frame, cv::Mat* bgr, cv::Mat* gray, cv::Mat* depth) {
  cv::Mat background(160, 240, CV_8U);
  cv::Mat square(40, 40, CV_8U);
  cv::RNG rng(1);
  rng.fill(background, cv::RNG::UNIFORM, 0, 255);
  rng.fill(square, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(background, background, {5, 5}, 1.5);
  cv::GaussianBlur(square, square, {5, 5}, 1.5);
  *depth = cv::Mat(160, 240, CV_32F, cv::Scalar(5.f));
  const cv::Rect where(30 + 3 * frame, 40, 40, 40);
  square.copyTo(background(where));
  (*depth)(where) = 1.f;
  *gray = background;
  cv::cvtColor(background, *bgr, cv::COLOR_GRAY2BGR);
}

// Runs `filter` on frame `frame` of MakeFrame with three keypoints: the square's centre, the
// background left of it, and near its right edge.
FilterOutput FilterSquareFrame(SemanticFilter* filter, int frame) {
  cv::Mat bgr, gray, depth;
  MakeFrame(frame, &bgr, &gray, &depth);
  KeypointSet set;
  const int x = 30 + 3 * frame;
  set.keypoints = {cv::KeyPoint(x + 20.f, 60.f, 7.f), cv::KeyPoint(x - 12.f, 60.f, 7.f),
                   cv::KeyPoint(x + 38.f, 45.f, 7.f)};
  FilterInput input;
  input.frame_id = frame;
  input.bgr = &bgr;
  input.gray = &gray;
  input.depth_m = &depth;
  input.keypoints = &set;
  return filter->Filter(input);
}

TEST(SemanticFilter, DeterministicScheduleAndCarriedMasks) {
  // Points tracked per object when carrying (grid x grid), on full- or half-resolution images.
  for (const auto& [grid, downscale] :
       std::vector<std::pair<int, int>>{{8, 1}, {4, 1}, {4, 2}, {2, 2}}) {
    SCOPED_TRACE(testing::Message() << grid << "x" << grid << " / " << downscale);
    auto provider = std::make_unique<SquareProvider>();
    provider->refine.dilation_px = 0;
    SquareProvider* raw = provider.get();
    SemanticOptions options;
    options.detect_every = 4;
    options.carry_grid = grid;
    options.carry_downscale = downscale;
    options.refine.dilation_px = 0;
    SemanticFilter filter(std::move(provider), options);
    for (int frame = 0; frame < 10; ++frame) {
      const FilterOutput out = FilterSquareFrame(&filter, frame);
      SCOPED_TRACE(frame);
      EXPECT_EQ(filter.last_was_detection(), frame % 4 == 0);
      // The carried box follows the square (3 px per frame) to a fraction of a pixel (before
      // session 35, LK windows reaching into the static background lagged 1.1 px in 3 frames).
      ASSERT_EQ(filter.current().objects.size(), 1u);
      EXPECT_NEAR(filter.current().objects[0].detection.box.x, 30.f + 3.f * frame, 0.3f);
      EXPECT_NEAR(filter.current().objects[0].detection.box.y, 40.f, 0.3f);
      EXPECT_FALSE(out.keep[0]);  // centre of the moving square, also between detections
      EXPECT_TRUE(out.keep[1]);   // background left of it
      EXPECT_FALSE(out.keep[2]);  // near its moving right edge
    }
    EXPECT_EQ(raw->calls, (std::vector<FrameId>{0, 4, 8}));
  }
  SemanticOptions bad;
  bad.carry_grid = 1;
  EXPECT_THROW(bad.Validate(), InputError);
  bad.carry_grid = 17;
  EXPECT_THROW(bad.Validate(), InputError);
  for (int downscale : {0, 3, 4}) {
    SemanticOptions wrong;
    wrong.carry_downscale = downscale;
    EXPECT_THROW(wrong.Validate(), InputError);
  }
}

// Quiet scenes: after two detections without a dynamic object, only every 8th frame is detected,
// until a detection finds one again; the schedule is the same with a pipelined detector.
class AppearingSquareProvider : public SquareProvider {
 public:
  DynamicObjects Masks(const MaskQuery& query) override {
    DynamicObjects out = SquareProvider::Masks(query);
    if (query.frame_id < appears_at) {
      out.objects.clear();
      out.mask.setTo(0);
    }
    return out;
  }
  FrameId appears_at = 0;
};

// The frames `provider` was asked for over frames 0 .. num_frames - 1 of FilterSquareFrame, with
// detect_every 4 and the given latency.
std::vector<FrameId> ScheduleCalls(std::unique_ptr<SquareProvider> provider,
                                   SemanticOptions options, int latency, int num_frames) {
  auto log = std::make_shared<std::vector<FrameId>>();
  provider->log = log;
  options.detect_every = 4;
  options.detector_latency = latency;
  {
    SemanticFilter filter(std::move(provider), options);
    for (int frame = 0; frame < num_frames; ++frame) FilterSquareFrame(&filter, frame);
  }
  return *log;
}

std::vector<FrameId> QuietScheduleCalls(int quiet_every, int latency, FrameId appears_at) {
  auto provider = std::make_unique<AppearingSquareProvider>();
  provider->appears_at = appears_at;
  SemanticOptions options;
  options.quiet_detect_every = quiet_every;
  options.quiet_after_empty = 2;
  return ScheduleCalls(std::move(provider), options, latency, 30);
}

TEST(SemanticFilter, QuietScheduleDetectsLessOftenUntilAnObjectIsFound) {
  for (int latency : {0, 2}) {
    SCOPED_TRACE(latency);
    // Off: every 4th frame.
    EXPECT_EQ(QuietScheduleCalls(0, latency, 13),
              (std::vector<FrameId>{0, 4, 8, 12, 16, 20, 24, 28}));
    // Empty at 0 and 4: quiet from 8 on (8, 16 detected); the square is found at 16 and every
    // 4th frame is detected again.
    EXPECT_EQ(QuietScheduleCalls(8, latency, 13), (std::vector<FrameId>{0, 4, 8, 16, 20, 24, 28}));
    // An object in every detection: never quiet.
    EXPECT_EQ(QuietScheduleCalls(8, latency, 0),
              (std::vector<FrameId>{0, 4, 8, 12, 16, 20, 24, 28}));
  }
  SemanticOptions bad;
  bad.quiet_detect_every = 6;  // not a multiple of detect_every (4)
  EXPECT_THROW(bad.Validate(), InputError);
  bad.quiet_detect_every = -4;
  EXPECT_THROW(bad.Validate(), InputError);
  bad.quiet_detect_every = 8;
  bad.quiet_after_empty = 0;
  EXPECT_THROW(bad.Validate(), InputError);
}

// Steady scenes: after two detections in a row agreed with the objects carried to them, only every
// 8th frame is detected, until one does not. ExtraObjectProvider adds a static second object at
// one frame: that detection and the next (whose carried objects still hold it) disagree.
class ExtraObjectProvider : public SquareProvider {
 public:
  DynamicObjects Masks(const MaskQuery& query) override {
    DynamicObjects out = SquareProvider::Masks(query);
    if (query.frame_id == extra_at) {
      Detection d;
      d.box = cv::Rect2f(180.f, 100.f, 30.f, 30.f);
      d.class_id = 0;
      const RefinedMask r = AddRefinedBoxMask(d.box, *query.depth_m, refine, 0.f, &out.mask);
      out.objects.push_back({d, r.depth_m});
    }
    return out;
  }
  static constexpr FrameId kNever = std::numeric_limits<FrameId>::max();
  FrameId extra_at = kNever;
};

std::vector<FrameId> SteadyScheduleCalls(int steady_every, double min_iou, int latency,
                                         FrameId extra_at) {
  auto provider = std::make_unique<ExtraObjectProvider>();
  provider->extra_at = extra_at;
  provider->refine.dilation_px = 0;  // Masks on the square only: the carried boxes follow it.
  SemanticOptions options;
  options.steady_detect_every = steady_every;
  options.steady_after = 2;
  options.steady_min_iou = min_iou;
  options.refine.dilation_px = 0;
  return ScheduleCalls(std::move(provider), options, latency, 40);
}

TEST(SemanticFilter, SteadyScheduleDetectsLessOftenWhileDetectionsAgreeWithTheCarriedObjects) {
  const std::vector<FrameId> every4{0, 4, 8, 12, 16, 20, 24, 28, 32, 36};
  for (int latency : {0, 2}) {
    SCOPED_TRACE(latency);
    EXPECT_EQ(SteadyScheduleCalls(0, 0.7, latency, 16), every4);  // off
    // Frame 0 has nothing carried (disagrees); 4 and 8 agree: steady from 8 on (12 skipped).
    // 16 finds a second object and 20 has it carried but not detected: every 4th frame until 24
    // and 28 agree; then 32 (36 skipped).
    EXPECT_EQ(SteadyScheduleCalls(8, 0.7, latency, 16),
              (std::vector<FrameId>{0, 4, 8, 16, 20, 24, 28, 32}));
    // Without the extra object: steady from 8 to the end.
    EXPECT_EQ(SteadyScheduleCalls(8, 0.7, latency, ExtraObjectProvider::kNever),
              (std::vector<FrameId>{0, 4, 8, 16, 24, 32}));
  }
  // Inline, a detection is compared with the objects carried to the previous frame: the square
  // has moved 3 px since (IoU 37/43 = 0.86), below a 0.95 gate: never steady. Pipelined, the
  // objects were carried to the detected frame itself, and they agree.
  EXPECT_EQ(SteadyScheduleCalls(8, 0.95, 0, ExtraObjectProvider::kNever), every4);
  EXPECT_EQ(SteadyScheduleCalls(8, 0.95, 2, ExtraObjectProvider::kNever),
            (std::vector<FrameId>{0, 4, 8, 16, 24, 32}));
  SemanticOptions bad;
  bad.steady_detect_every = 6;  // not a multiple of detect_every (4)
  EXPECT_THROW(bad.Validate(), InputError);
  bad.steady_detect_every = 8;
  bad.steady_after = 0;
  EXPECT_THROW(bad.Validate(), InputError);
  bad.steady_after = 2;
  for (double iou : {0.0, 0.4, -0.5, 1.5, std::nan("")}) {
    bad.steady_min_iou = iou;
    EXPECT_THROW(bad.Validate(), InputError) << iou;
  }
  bad.steady_min_iou = 1.0;
  EXPECT_NO_THROW(bad.Validate());
  bad.steady_detect_every = -8;
  EXPECT_THROW(bad.Validate(), InputError);
  // Carried objects live max_carried_frames (15) frames: a detection every 16th frame inline is
  // the longest gap, and 16 at a latency of 2 is too long.
  bad.steady_detect_every = 16;
  EXPECT_NO_THROW(bad.Validate());
  bad.detector_latency = 2;
  EXPECT_THROW(bad.Validate(), InputError);
  bad.detector_latency = 0;
  bad.steady_detect_every = 20;
  EXPECT_THROW(bad.Validate(), InputError);
}

// Pipelined detection: frame k's detection runs on a worker and is used (carried by flow) at frame
// k + latency; the calls and results do not depend on thread timing.
std::vector<std::vector<bool>> RunPipelined(int latency, std::vector<FrameId>* calls, std::vector<bool>* arrived) {
  auto provider = std::make_unique<SquareProvider>();
  provider->refine.dilation_px = 0;
  auto log = std::make_shared<std::vector<FrameId>>();
  provider->log = log;
  SemanticOptions options;
  options.detect_every = 3;
  options.detector_latency = latency;
  options.refine.dilation_px = 0;
  std::vector<std::vector<bool>> keeps;
  {
    SemanticFilter filter(std::move(provider), options);
    for (int frame = 0; frame < 10; ++frame) {
      keeps.push_back(FilterSquareFrame(&filter, frame).keep);
      arrived->push_back(filter.last_was_detection());
    }
  }  // Destroying the filter waits for its worker: the log is complete and no longer shared.
  *calls = *log;
  return keeps;
}

TEST(SemanticFilter, PipelinedDetectionIsUsedLatencyFramesLaterAndCarried) {
  std::vector<FrameId> calls;
  std::vector<bool> arrived;
  const auto keeps = RunPipelined(2, &calls, &arrived);
  EXPECT_EQ(calls, (std::vector<FrameId>{0, 3, 6, 9}));
  EXPECT_EQ(arrived, (std::vector<bool>{false, false, true, false, false, true, false, false, true, false}));
  // Nothing is masked before the first detection arrives (frames 0, 1) ...
  EXPECT_EQ(keeps[0], (std::vector<bool>{true, true, true}));
  EXPECT_EQ(keeps[1], (std::vector<bool>{true, true, true}));
  // ... afterwards the square is masked on every frame (detected 2 frames ago, carried by flow).
  for (int frame = 2; frame < 10; ++frame) {
    SCOPED_TRACE(frame);
    EXPECT_FALSE(keeps[frame][0]);
    EXPECT_TRUE(keeps[frame][1]);
  }
  // Same input, same output, whatever the worker's timing.
  std::vector<FrameId> calls2;
  std::vector<bool> arrived2;
  EXPECT_EQ(RunPipelined(2, &calls2, &arrived2), keeps);
  EXPECT_THROW(
      {
        SemanticOptions bad;
        bad.detect_every = 2;
        bad.detector_latency = 2;
        bad.Validate();
      },
      InputError);
}

// A provider whose calls wait (up to 0.3 s) for a second call to start: two calls that can overlap
// always do, whatever the machine's load, and the most that ran at once is recorded.
class OverlapProvider : public MaskProvider {
 public:
  explicit OverlapProvider(std::shared_ptr<std::atomic<int>> max_in_flight)
      : max_in_flight_(std::move(max_in_flight)) {}
  std::string name() const override { return "overlap"; }
  DynamicObjects Masks(const MaskQuery& query) override {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      const int now = ++in_flight_;
      if (now > max_in_flight_->load()) max_in_flight_->store(now);
      changed_.notify_all();
      changed_.wait_for(lock, std::chrono::milliseconds(300), [this] { return in_flight_ >= 2; });
      --in_flight_;
    }
    DynamicObjects out;
    out.mask = cv::Mat::zeros(query.bgr->size(), CV_8U);
    return out;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  int in_flight_ = 0;
  std::shared_ptr<std::atomic<int>> max_in_flight_;
};

// A caller that goes on after the System dropped frames whose front ends had run hands in ids
// that were already seen: the detection in flight (frame 4's, due at frame 6) is dropped, and the
// new frame 4 starts its own only after it ended. Before session 54 both ran on the one provider
// at the same time.
TEST(SemanticFilter, RepeatedFrameIdsNeverRunTwoDetectionsAtOnce) {
  auto max_in_flight = std::make_shared<std::atomic<int>>(0);
  SemanticOptions options;
  options.detect_every = 4;
  options.detector_latency = 2;
  SemanticFilter filter(std::make_unique<OverlapProvider>(max_in_flight), options);
  for (int frame : {0, 1, 2, 3, 4, 5, 4, 5, 6, 7, 8}) FilterSquareFrame(&filter, frame);
  EXPECT_EQ(max_in_flight->load(), 1);
}

// A mask file gives masks but no objects: to the quiet schedule every read looks empty. With
// EveryFrameSchedule (what `dynorb run` uses for mask and box files and the oracle) every frame is
// read and masked; with only detect_every 1 and --mode semantic's schedules, frames 2-7 and 9-11
// would go unread and unmasked (sessions 52-53: the bench's view-loss reference).
class MaskOnlyProvider : public SquareProvider {
 public:
  DynamicObjects Masks(const MaskQuery& query) override {
    DynamicObjects out = SquareProvider::Masks(query);
    out.objects.clear();
    return out;
  }
};

TEST(SemanticFilter, EveryFrameScheduleReadsAFileProviderOnEveryFrame) {
  SemanticOptions mode_defaults;  // as in --mode semantic
  mode_defaults.quiet_detect_every = 8;
  mode_defaults.steady_detect_every = 8;
  mode_defaults.detector_latency = 2;
  const SemanticOptions every = EveryFrameSchedule(mode_defaults);
  EXPECT_EQ(every.detect_every, 1);
  EXPECT_EQ(every.detector_latency, 0);
  EXPECT_NO_THROW(every.Validate());
  SemanticOptions detect_every_only = mode_defaults;
  detect_every_only.detect_every = 1;
  detect_every_only.detector_latency = 0;
  for (const auto& [options, expected] :
       std::vector<std::pair<SemanticOptions, std::vector<FrameId>>>{
           {every, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}}, {detect_every_only, {0, 1, 8}}}) {
    auto provider = std::make_unique<MaskOnlyProvider>();
    provider->refine.dilation_px = 0;
    auto log = std::make_shared<std::vector<FrameId>>();
    provider->log = log;
    SemanticFilter filter(std::move(provider), options);
    int masked = 0;
    for (int frame = 0; frame < 12; ++frame)
      masked += FilterSquareFrame(&filter, frame).keep[0] ? 0 : 1;
    EXPECT_EQ(*log, expected);
    EXPECT_EQ(masked, static_cast<int>(expected.size()));  // the square's centre, where read
  }
}

TEST(FileMaskProvider, BoxesAndMasksLists) {
  const fs::path dir = fs::temp_directory_path() / "dynorb_semantic_test_files";
  fs::create_directories(dir);
  {
    std::ofstream(dir / "boxes.txt") << "# ts x y w h class score\n1.0 10 10 20 20 0 0.9\n1.0 50 5 5 5\n2.0 0 0 8 8\n";
    cv::Mat m = cv::Mat::zeros(40, 80, CV_8U);
    m(cv::Rect(0, 0, 10, 10)) = 3;
    cv::imwrite((dir / "m1.png").string(), m);
    std::ofstream(dir / "masks.txt") << "1.0 m1.png\n";
  }
  const cv::Mat bgr(40, 80, CV_8UC3, cv::Scalar(0, 0, 0));
  DepthRefineOptions refine;
  refine.dilation_px = 0;
  FileMaskProvider boxes((dir / "boxes.txt").string(), MaskFileKind::kBoxes, refine);
  EXPECT_EQ(boxes.size(), 2u);
  const DynamicObjects at1 = boxes.Masks({0, 1.001, &bgr, nullptr});
  ASSERT_EQ(at1.objects.size(), 2u);
  EXPECT_FLOAT_EQ(at1.objects[0].detection.score, 0.9f);
  EXPECT_EQ(cv::countNonZero(at1.mask), 400 + 25);
  EXPECT_EQ(cv::countNonZero(boxes.Masks({0, 1.5, &bgr, nullptr}).mask), 0);
  FileMaskProvider masks((dir / "masks.txt").string(), MaskFileKind::kMasks, refine);
  EXPECT_EQ(cv::countNonZero(masks.Masks({0, 1.0, &bgr, nullptr}).mask), 100);
  // Bad input names the file and line.
  for (const auto& [text, message] : std::vector<std::pair<std::string, std::string>>{
           {"1.0 10 10 -5 5", "bad.txt:1: expected 'timestamp x y w h"},
           {"# c\n1.0 10 20 30 40 1.5",
            "bad.txt:2: class_id must be a non-negative integer, got '1.5'"},
           {"1.0 10 20 30 40 -2", "class_id must be a non-negative integer"},
           {"1.0 10 20 30 40 3 -7", "score must be a number in [0, 1], got '-7'"},
           {"1.0 10 20 30 40 3 0.5x", "score must be a number in [0, 1], got '0.5x'"},
           {"1.0 10 20 30 nan", "expected 'timestamp x y w h"},
           {"1.0 10 20 30 40 3 0.5 9", "expected 'timestamp x y w h"}}) {
    std::ofstream(dir / "bad.txt") << text << "\n";
    try {
      FileMaskProvider bad((dir / "bad.txt").string(), MaskFileKind::kBoxes, refine);
      ADD_FAILURE() << "no error for " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
  std::ofstream(dir / "missing.txt") << "1.0 nothere.png\n";
  FileMaskProvider missing((dir / "missing.txt").string(), MaskFileKind::kMasks, refine);
  EXPECT_THROW(missing.Masks({0, 1.0, &bgr, nullptr}), InputError);
  EXPECT_THROW(FileMaskProvider((dir / "none.txt").string(), MaskFileKind::kMasks, refine), InputError);
  fs::remove_all(dir);
}

TEST(SemanticDetector, BadModelFilesAndClassesAreClearErrors) {
  const fs::path dir = fs::temp_directory_path() / "dynorb_semantic_test_models";
  fs::remove_all(dir);
  DetectorOptions options;
  options.models_dir = dir.string();
  ExpectInputError(options, "fetch_models.sh");
  options.model = "yolo_v99";
  EXPECT_THROW(options.Validate(), InputError);
  EXPECT_THROW(ResolveDynamicClasses({"person", "pedestrian"}, CocoClassNames()), InputError);
  EXPECT_EQ(ResolveDynamicClasses({"motorcycle"}, CocoClassNames())[3], true);
  if (!fs::is_directory(kModels)) GTEST_SKIP() << "no shared models at " << kShared;
  // cfg/weights mismatch: the body cfg with the COCO weights.
  fs::create_directories(dir / "yolo_fastest_1.1_body");
  fs::copy_file(kModels + "/yolo_fastest_1.1_body/yolo-fastest-1.1_body.cfg",
                dir / "yolo_fastest_1.1_body/yolo-fastest-1.1_body.cfg");
  fs::copy_file(kModels + "/yolo_fastest_1.1/yolo-fastest-1.1.weights",
                dir / "yolo_fastest_1.1_body/yolo-fastest-1.1_body.weights");
  fs::copy_file(kModels + "/yolo_fastest_1.1_body/body.names", dir / "yolo_fastest_1.1_body/body.names");
  options.model = "yolo_fastest_1.1_body";
  ExpectInputError(options, "cfg/weights mismatch");
  // A names file one class short: every class id after it would shift, cut heads or not.
  fs::create_directories(dir / "yolo_fastest_1.1");
  for (const char* file : {"yolo-fastest-1.1.cfg", "yolo-fastest-1.1.weights"}) {
    fs::copy_file(kModels + "/yolo_fastest_1.1/" + file, dir / "yolo_fastest_1.1" / file);
  }
  {
    std::ifstream in(kModels + "/yolo_fastest_1.1/coco.names");
    std::ofstream out(dir / "yolo_fastest_1.1/coco.names");
    std::string line;
    while (std::getline(in, line)) {
      if (line != "bicycle") out << line << "\n";
    }
  }
  options.model = "yolo_fastest_1.1";
  options.classes = {"person", "dog"};
  ExpectInputError(options, "predicts 80 classes, but");
  options.prune_heads = false;
  ExpectInputError(options, "unexpected network output");
  options.classes.clear();
  options.prune_heads = true;
  // Corrupt ONNX.
  fs::create_directories(dir / "fastestdet");
  std::ofstream(dir / "fastestdet/FastestDet.onnx") << "not an onnx file";
  fs::copy_file(kModels + "/fastestdet/coco.names", dir / "fastestdet/coco.names");
  options.model = "fastestdet";
  ExpectInputError(options, "FastestDet.onnx");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dynorb
