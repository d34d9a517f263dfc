#include "dynamic_labels.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include <opencv2/imgcodecs.hpp>

#include <opencv2/imgproc.hpp>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

cv::KeyPoint At(float x, float y, int octave) { return cv::KeyPoint(cv::Point2f(x, y), 31.f, -1.f, 0.f, octave); }

// A 20×20 object at x, y in [40, 60) on a 100×100 image.
cv::Mat SquareMask() {
  cv::Mat mask = cv::Mat::zeros(100, 100, CV_8U);
  mask(cv::Rect(40, 40, 20, 20)).setTo(1);
  return mask;
}

TEST(KeypointLabelStats, PixelTruthAndScaleAwareSupportTruth) {
  KeypointLabelStats stats(1.2);
  const std::vector<cv::KeyPoint> kps = {
      At(50, 50, 0),  // on the object, removed: TP for both truths
      At(37, 50, 0),  // 3 px left of the object, octave 0: its circle reaches x = 40 -> support truth; removed
      At(36, 50, 0),  // 4 px off, octave 0: radius 3 misses -> FP for both; removed
      At(35, 50, 3),  // 5 px off, octave 3: radius 3 * 1.728 = 5.2 px reaches the object; removed
      At(37, 45, 0),  // 3 px off, kept: a miss (FN) for the support truth only
      At(10, 10, 0),  // far away, kept: TN
      At(45, 45, 0),  // on the object, kept: FN for both
  };
  const std::vector<bool> keep = {false, false, false, false, true, true, true};
  stats.Add(kps, keep, SquareMask());
  const nlohmann::json j = stats.ToJson();
  EXPECT_EQ(j["true_positive"], 1);
  EXPECT_EQ(j["false_positive"], 3);
  EXPECT_EQ(j["false_negative"], 1);
  EXPECT_EQ(j["true_negative"], 2);
  EXPECT_EQ(j["false_positive_within_3px"], 1);  // only the keypoint 3 px off counts as "within 3 px"
  const nlohmann::json& s = j["support"];
  EXPECT_EQ(s["true_positive"], 3);   // on, 3 px at octave 0, 5 px at octave 3
  EXPECT_EQ(s["false_positive"], 1);  // 4 px at octave 0
  EXPECT_EQ(s["false_negative"], 2);  // kept outline keypoint + kept keypoint on the object
  EXPECT_DOUBLE_EQ(s["precision"].get<double>(), 0.75);
  EXPECT_DOUBLE_EQ(s["recall"].get<double>(), 0.6);
}

// Recall per object id: a small mover's misses are not hidden in a large one's totals; ignored
// (still) objects and keypoints off every object are not counted there.
TEST(KeypointLabelStats, RecallPerObjectId) {
  cv::Mat mask = cv::Mat::zeros(100, 100, CV_8U);
  mask(cv::Rect(0, 0, 50, 100)).setTo(1);   // a person, id 1
  mask(cv::Rect(60, 60, 10, 10)).setTo(4);  // a small box, id 4
  mask(cv::Rect(80, 10, 10, 10)).setTo(5);  // an object standing still, id 5
  cv::Mat still = cv::Mat::zeros(100, 100, CV_8U);
  still.setTo(255, mask == 5);
  const std::vector<cv::KeyPoint> kps = {At(10, 10, 0), At(20, 20, 0), At(30, 30, 0),
                                         At(40, 40, 0), At(62, 62, 0), At(67, 67, 0),
                                         At(85, 15, 0), At(75, 90, 0)};
  // The person's 4 keypoints and one of the box's 2 removed, the still object's and a background
  // keypoint removed too.
  const std::vector<bool> keep = {false, false, false, false, false, true, false, false};
  KeypointLabelStats stats(1.2);
  stats.Add(kps, keep, mask, still);
  stats.Add(kps, keep, mask, still);  // a second frame: the counts add up
  const nlohmann::json j = stats.ToJson();
  const nlohmann::json& by = j["by_object"];
  ASSERT_EQ(by.size(), 2u);
  EXPECT_EQ(by["1"]["true_positive"], 8);
  EXPECT_EQ(by["1"]["false_negative"], 0);
  EXPECT_DOUBLE_EQ(by["1"]["recall"].get<double>(), 1.0);
  EXPECT_EQ(by["4"]["true_positive"], 2);
  EXPECT_EQ(by["4"]["false_negative"], 2);
  EXPECT_DOUBLE_EQ(by["4"]["recall"].get<double>(), 0.5);
  EXPECT_FALSE(by.contains("5"));
  EXPECT_EQ(j["true_positive"], 10);
  EXPECT_EQ(j["false_negative"], 2);
  EXPECT_EQ(j["ignored"], 2);
  EXPECT_TRUE(KeypointLabelStats(1.2).ToJson()["by_object"].empty());
}

// The per-frame truth computed once equals the definitions it replaces: "within 3 px" = the object
// mask dilated with the 7x7 ellipse (still objects removed first), on random blobs and keypoints.
TEST(KeypointTruth, NearIsTheEllipseDilationOfTheCountedObjects) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 99.f);
  std::uniform_int_distribution<int> octave(0, 3);
  for (int trial = 0; trial < 20; ++trial) {
    cv::Mat mask = cv::Mat::zeros(100, 100, CV_8U), still = cv::Mat::zeros(100, 100, CV_8U);
    for (int b = 0; b < 4; ++b) {
      const cv::Point c(static_cast<int>(u(rng)), static_cast<int>(u(rng)));
      cv::circle(mask, c, 3 + b * 3, cv::Scalar(b + 1), cv::FILLED);
    }
    still.setTo(255, mask == 2);
    std::vector<cv::KeyPoint> kps;
    for (int k = 0; k < 300; ++k) kps.push_back(At(u(rng), u(rng), octave(rng)));
    for (const cv::Mat& ignore : {cv::Mat(), still}) {
      cv::Mat objects = mask != 0, near;
      if (!ignore.empty()) objects.setTo(0, ignore != 0);
      cv::dilate(objects, near, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(7, 7)));
      const KeypointTruth t = ComputeKeypointTruth(kps, mask, ignore, 1.2);
      ASSERT_TRUE(t.has_mask);
      for (size_t i = 0; i < kps.size(); ++i) {
        const int x = static_cast<int>(std::lround(kps[i].pt.x)), y = static_cast<int>(std::lround(kps[i].pt.y));
        const bool ignored = !ignore.empty() && ignore.at<uint8_t>(y, x) != 0;
        ASSERT_EQ(t.ignored[i] != 0, ignored) << i;
        if (ignored) continue;
        EXPECT_EQ(t.on_object[i] != 0, mask.at<uint8_t>(y, x) != 0) << i;
        EXPECT_EQ(t.near[i] != 0, near.at<uint8_t>(y, x) != 0) << trial << " " << i;
        EXPECT_TRUE(!t.on_object[i] || t.support[i]) << i;
      }
    }
  }
}

TEST(CountOnObjects, PixelAndSupportCountsIgnoringStillObjects) {
  const std::vector<cv::KeyPoint> kps = {At(50, 50, 0), At(37, 50, 0), At(35, 50, 3), At(36, 50, 0), At(10, 10, 0)};
  const KeypointsOnObjects c = CountOnObjects(kps, SquareMask(), cv::Mat(), 1.2);
  EXPECT_EQ(c.pixel, 1);    // only the keypoint on the object
  EXPECT_EQ(c.support, 3);  // + 3 px off at octave 0 and 5 px off at octave 3
  const cv::Mat still = SquareMask() * 255;
  const KeypointsOnObjects none = CountOnObjects(kps, SquareMask(), still, 1.2);
  EXPECT_EQ(none.pixel, 0);
  EXPECT_EQ(none.support, 0);
  EXPECT_EQ(CountOnObjects(kps, cv::Mat(), cv::Mat(), 1.2).support, 0);  // no mask, nothing counted
}

TEST(KeypointLabelStats, StillObjectsAreNeitherTruthNorSupport) {
  KeypointLabelStats stats(1.2);
  const cv::Mat mask = SquareMask();
  const cv::Mat still = mask * 255;  // the whole object stands still at this frame
  const std::vector<cv::KeyPoint> kps = {At(50, 50, 0), At(37, 50, 0)};
  stats.Add(kps, {false, false}, mask, still);
  const nlohmann::json j = stats.ToJson();
  EXPECT_EQ(j["ignored"], 1);                        // the keypoint on the still object
  EXPECT_EQ(j["false_positive"], 1);                 // the one beside it is a plain false positive
  EXPECT_EQ(j["support"]["false_positive"], 1);      // ... for the support truth as well
  EXPECT_EQ(j["support"]["true_positive"], 0);
}

TEST(KeypointLabelStats, NoKeepVectorMeansNothingRemoved) {
  KeypointLabelStats stats(1.2);
  stats.Add({At(50, 50, 0), At(38, 50, 0)}, {}, SquareMask());
  const nlohmann::json j = stats.ToJson();
  EXPECT_EQ(j["false_negative"], 1);
  EXPECT_EQ(j["support"]["false_negative"], 2);
  EXPECT_EQ(j["support"]["recall"], 0.0);
}

// Erased landmarks judged by the keypoint where they were made: two masks (an object at the first
// stamp, none at the second), landmarks from both stamps and one without a known origin.
TEST(ClassifyErasedLandmarks, ByTheMaskAtTheirOrigin) {
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "erased_landmarks";
  std::filesystem::create_directories(dir);
  cv::imwrite((dir / "a.png").string(), SquareMask() * 3);
  cv::imwrite((dir / "b.png").string(), cv::Mat::zeros(100, 100, CV_8U));
  std::ofstream(dir / "masks.txt") << "1.0 a.png\n2.0 b.png\n";
  const std::optional<MaskGroundTruth> masks = MaskGroundTruth::Open(dir.string());
  ASSERT_TRUE(masks.has_value());
  auto erased = [](double stamp, float x, float y, bool known) {
    ErasedLandmark e;
    e.origin.known = known;
    e.origin.timestamp_s = stamp;
    e.origin.keypoint = At(x, y, 0);
    return e;
  };
  const OriginTruth truth = ClassifyErasedLandmarks(
      {erased(1.0, 50, 50, true), erased(1.0, 10, 10, true), erased(2.0, 50, 50, true),
       erased(1.0, 45, 45, false), erased(1.0, 59.4f, 40, true)},
      *masks);
  EXPECT_EQ(truth.with_origin, 4);
  EXPECT_EQ(truth.made_on_objects, 2);  // (50, 50) and (59.4, 40) at stamp 1.0
  EXPECT_EQ(truth.object_id, (std::vector<uint8_t>{3, 0, 0, 0, 3}));  // the mask's value: 3
  EXPECT_EQ(truth.by_object, (std::map<int, long long>{{3, 2}}));
  // A stamp without a mask is not judged.
  const OriginTruth later = ClassifyErasedLandmarks({erased(3.0, 50, 50, true)}, *masks);
  EXPECT_EQ(later.with_origin, 0);
  EXPECT_EQ(later.object_id, (std::vector<uint8_t>{0}));
}

// Masks must have the images' size: another size would be read at the wrong pixels.
TEST(MaskGroundTruth, RefusesMasksOfAnotherSize) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "mask_size";
  std::filesystem::create_directories(dir);
  cv::imwrite((dir / "a.png").string(), cv::Mat::zeros(100, 100, CV_8U));
  std::ofstream(dir / "masks.txt") << "1.0 a.png\n";
  const std::optional<MaskGroundTruth> same =
      MaskGroundTruth::Open(dir.string(), cv::Size(100, 100));
  ASSERT_TRUE(same.has_value());
  EXPECT_EQ(same->MaskAt(1.0).size(), cv::Size(100, 100));
  const std::optional<MaskGroundTruth> other =
      MaskGroundTruth::Open(dir.string(), cv::Size(640, 480));
  ASSERT_TRUE(other.has_value());
  try {
    other->MaskAt(1.0);
    ADD_FAILURE() << "no error for a 100x100 mask of 640x480 images";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(),
                ::testing::HasSubstr("a.png: the mask is 100x100 but the images are 640x480"));
  }
}

}  // namespace
}  // namespace dynorb
