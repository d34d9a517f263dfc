#include "map_export.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

namespace dynorb {
namespace {

namespace fs = std::filesystem;

LandmarkSummary Landmark(double x, bool known, double stamp, float u, float v) {
  LandmarkSummary l;
  l.point_in_world = Eigen::Vector3d(x, 2.0 * x, 1.0);
  l.origin.known = known;
  l.origin.timestamp_s = stamp;
  l.origin.keypoint = cv::KeyPoint(cv::Point2f(u, v), 31.f);
  return l;
}

// A two-frame TUM folder: frame 1.0 is blue with one red pixel at (3, 2), frame 2.0 is green.
std::string TwoFrameSequence() {
  const fs::path dir = fs::path(::testing::TempDir()) / "map_export_seq";
  fs::remove_all(dir);
  fs::create_directories(dir);
  cv::Mat first(6, 8, CV_8UC3, cv::Scalar(255, 0, 0));
  first.at<cv::Vec3b>(2, 3) = cv::Vec3b(0, 0, 255);
  cv::imwrite((dir / "a.png").string(), first);
  cv::imwrite((dir / "b.png").string(), cv::Mat(6, 8, CV_8UC3, cv::Scalar(0, 255, 0)));
  cv::imwrite((dir / "d.png").string(), cv::Mat(6, 8, CV_16UC1, cv::Scalar(5000)));
  std::ofstream(dir / "rgb.txt") << "1.000000 a.png\n2.000000 b.png\n";
  std::ofstream(dir / "depth.txt") << "1.000000 d.png\n2.000000 d.png\n";
  return dir.string();
}

TEST(MapExport, ColoursComeFromTheOriginKeyframesImageAtTheKeypoint) {
  const TumSequence sequence(TwoFrameSequence());
  const std::vector<LandmarkSummary> landmarks = {
      Landmark(0.1, true, 1.0, 3.2f, 1.8f),   // nearest pixel (3, 2): red
      Landmark(0.2, true, 1.0, 0.f, 0.f),     // blue
      Landmark(0.3, true, 2.0, 7.f, 5.f),     // green
      Landmark(0.4, false, 1.0, 3.f, 2.f),    // origin unknown: grey
      Landmark(0.5, true, 9.0, 3.f, 2.f),     // stamp not in the sequence: grey
      Landmark(0.6, true, 2.0, -4.f, 40.f)};  // off the image: clamped to the nearest pixel, green
  std::vector<LandmarkOrigin> origins;
  for (const LandmarkSummary& l : landmarks) origins.push_back(l.origin);
  const std::vector<cv::Vec3b> c = LandmarkColours(origins, sequence);
  ASSERT_EQ(c.size(), landmarks.size());
  EXPECT_EQ(c[0], cv::Vec3b(255, 0, 0));  // red, green, blue order
  EXPECT_EQ(c[1], cv::Vec3b(0, 0, 255));
  EXPECT_EQ(c[2], cv::Vec3b(0, 255, 0));
  EXPECT_EQ(c[3], cv::Vec3b(128, 128, 128));
  EXPECT_EQ(c[4], cv::Vec3b(128, 128, 128));
  EXPECT_EQ(c[5], cv::Vec3b(0, 255, 0));

  const PointCloud cloud = MapPointCloud(landmarks, c, {1, 0, 0, 0, 0, 1});
  ASSERT_EQ(cloud.points.size(), landmarks.size());
  EXPECT_EQ(cloud.points[2], Eigen::Vector3f(0.3f, 0.6f, 1.f));
  ASSERT_EQ(cloud.flags.size(), 1u);
  EXPECT_EQ(cloud.flags[0].first, "dynamic_object_id");
  EXPECT_TRUE(MapPointCloud(landmarks, c, {}).flags.empty());
  EXPECT_THROW(MapPointCloud(landmarks, {}, {}), std::logic_error);
}

TEST(MapExport, TruthJsonCountsAndFraction) {
  OriginTruth truth;
  truth.with_origin = 8;
  truth.made_on_objects = 2;
  truth.by_object = {{1, 1}, {4, 1}};
  const nlohmann::json j = MapTruthJson(truth, 10);
  EXPECT_EQ(j["landmarks"], 10);
  EXPECT_EQ(j["origin_known"], 8);
  EXPECT_EQ(j["made_on_dynamic_objects"], 2);
  EXPECT_EQ(j["by_object"], (nlohmann::json{{"1", 1}, {"4", 1}}));
  EXPECT_DOUBLE_EQ(j["fraction"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(MapTruthJson(OriginTruth(), 0)["fraction"].get<double>(), 0.0);
}

}  // namespace
}  // namespace dynorb
