#include "dynorb/io/tum_sequence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "dynorb/core/error.h"
#include "dynorb/core/test_expect_error.h"
#include "dynorb/io/rgbd_image_io.h"
#include "dynorb/io/test_temp_dir.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;

using testing::ExpectInputError;

class TumSequenceTest : public testing::TempDirTest {
 protected:
  TumSequenceTest() : TempDirTest("dynorb_tum_seq_") {}
  static constexpr int kWidth = 8;
  static constexpr int kHeight = 6;

  void SetUp() override {
    TempDirTest::SetUp();
    fs::create_directories(dir_ / "rgb");
    fs::create_directories(dir_ / "depth");
  }
  void WriteText(const std::string& name, const std::string& content) { Write(name, content); }
  static cv::Mat RgbImage(int k) {
    cv::Mat rgb(kHeight, kWidth, CV_8UC3);
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u)
        rgb.at<cv::Vec3b>(v, u) = cv::Vec3b(10 * k + u, 20 + v, 200 - k);
    }
    return rgb;
  }
  static cv::Mat DepthRaw(int k) {
    cv::Mat raw(kHeight, kWidth, CV_16UC1);
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u)
        raw.at<uint16_t>(v, u) = static_cast<uint16_t>(1000 * k + 100 * v + u);
    }
    raw.at<uint16_t>(0, 0) = 0;      // no measurement
    raw.at<uint16_t>(1, 1) = 5000;   // exactly 1 m at factor 5000
    raw.at<uint16_t>(2, 2) = 65535;  // far end of the range
    return raw;
  }
  // Three frames at ~30 Hz. depth.txt has an extra stamp that must not be associated and the depth
  // stamps are a little after the rgb stamps.
  void WriteSequence() {
    std::string rgb_txt = "# color images\n# timestamp filename\n\n";
    std::string depth_txt = "# depth maps\n";
    for (int k = 0; k < 3; ++k) {
      const std::string rgb_name = "rgb/" + std::to_string(k) + ".png";
      const std::string depth_name = "depth/" + std::to_string(k) + ".png";
      ASSERT_TRUE(cv::imwrite((dir_ / rgb_name).string(), RgbImage(k)));
      ASSERT_TRUE(cv::imwrite((dir_ / depth_name).string(), DepthRaw(k)));
      rgb_txt += std::to_string(100.0 + k / 30.0) + " " + rgb_name + "\n";
      depth_txt += std::to_string(100.0 + k / 30.0 + 0.004) + " " + depth_name + "\n";
    }
    depth_txt += "200.0 depth/unused.png\n";
    WriteText("rgb.txt", rgb_txt);
    WriteText("depth.txt", depth_txt);
  }
  std::string folder() const { return dir_.string(); }

};

TEST_F(TumSequenceTest, StreamsFramesWithExactDepth) {
  WriteSequence();
  WriteText("groundtruth.txt", "# gt\n99.9 0 0 0 0 0 0 1\n100.1 1 2 3 0 0 0 1\n");
  TumSequence seq(folder());
  ASSERT_EQ(seq.size(), 3u);
  ASSERT_TRUE(seq.HasGroundTruth());
  ASSERT_EQ(seq.ground_truth().size(), 2u);
  EXPECT_DOUBLE_EQ(seq.ground_truth()[1].world_from_cam.translation.z(), 3.0);

  RgbdFrame frame;
  int k = 0;
  while (seq.Next(&frame)) {
    EXPECT_EQ(frame.index, static_cast<size_t>(k));
    EXPECT_NEAR(frame.timestamp_s, 100.0 + k / 30.0, 1e-6);
    EXPECT_NEAR(frame.depth_timestamp_s, 100.0 + k / 30.0 + 0.004, 1e-6);
    ASSERT_EQ(frame.rgb.type(), CV_8UC3);
    ASSERT_EQ(frame.depth_m.type(), CV_32FC1);
    ASSERT_EQ(frame.rgb.size(), cv::Size(kWidth, kHeight));
    ASSERT_EQ(frame.depth_m.size(), cv::Size(kWidth, kHeight));
    EXPECT_EQ(cv::norm(frame.rgb, RgbImage(k), cv::NORM_INF), 0.0);  // BGR preserved exactly
    const cv::Mat raw = DepthRaw(k);
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u) {
        ASSERT_EQ(frame.depth_m.at<float>(v, u),
                  static_cast<float>(raw.at<uint16_t>(v, u) / 5000.0));
      }
    }
    EXPECT_EQ(frame.depth_m.at<float>(0, 0), 0.0f);
    EXPECT_EQ(frame.depth_m.at<float>(1, 1), 1.0f);
    ++k;
  }
  EXPECT_EQ(k, 3);
  EXPECT_FALSE(seq.Next(&frame));
  seq.Rewind();
  ASSERT_TRUE(seq.Next(&frame));
  EXPECT_EQ(frame.index, 0u);
  // Random access gives the same frame.
  const RgbdFrame again = seq.Frame(2);
  EXPECT_EQ(again.index, 2u);
  EXPECT_EQ(cv::norm(again.rgb, RgbImage(2), cv::NORM_INF), 0.0);
}

TEST_F(TumSequenceTest, DepthFactorIsConfigurable) {
  WriteSequence();
  TumSequenceOptions options;
  options.depth_factor = 1000.0;
  const RgbdFrame frame = TumSequence(folder(), options).Frame(1);
  EXPECT_EQ(frame.depth_m.at<float>(1, 1), 5.0f);
  EXPECT_EQ(frame.depth_m.at<float>(3, 4), static_cast<float>(1304 / 1000.0));
  EXPECT_EQ(frame.depth_m.at<float>(2, 2), static_cast<float>(65.535));
}

TEST_F(TumSequenceTest, DepthRawToMetresIsExact) {
  cv::Mat raw(1, 5, CV_16UC1);
  const uint16_t values[] = {0, 1, 5000, 12345, 65535};
  for (int i = 0; i < 5; ++i) raw.at<uint16_t>(0, i) = values[i];
  const cv::Mat m = DepthRawToMetres(raw, 5000.0);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(m.at<float>(0, i), static_cast<float>(values[i] / 5000.0));
  EXPECT_EQ(m.at<float>(0, 2), 1.0f);
  EXPECT_EQ(m.at<float>(0, 3), 2.469f);
  // A different factor on the same thread must not reuse the previous table.
  EXPECT_EQ(DepthRawToMetres(raw, 1000.0).at<float>(0, 2), 5.0f);
}

TEST_F(TumSequenceTest, ExplicitAssociationsFile) {
  WriteSequence();
  WriteText("assoc.txt",
            "# rgb depth\n100.000000 rgb/0.png 100.004000 depth/0.png\n"
            "100.066667 rgb/2.png 100.070667 depth/2.png\n");
  TumSequenceOptions options;
  options.associations_file = "assoc.txt";
  TumSequence seq(folder(), options);
  ASSERT_EQ(seq.size(), 2u);
  EXPECT_EQ(seq.entries()[1].rgb_path, "rgb/2.png");
  EXPECT_DOUBLE_EQ(seq.entries()[1].depth_timestamp_s, 100.070667);
  EXPECT_EQ(cv::norm(seq.Frame(1).rgb, RgbImage(2), cv::NORM_INF), 0.0);
  EXPECT_FALSE(seq.HasGroundTruth());
  EXPECT_TRUE(seq.ground_truth().empty());
}

TEST_F(TumSequenceTest, BadListsAndFolders) {
  ExpectInputError([&] { TumSequence((dir_ / "nope").string()); }, "sequence folder not found");
  ExpectInputError([&] { TumSequence s(folder()); }, "rgb list not found");
  WriteSequence();
  const std::string good_rgb = "1.0 rgb/0.png\n2.0 rgb/1.png\n";
  WriteText("rgb.txt", "# header\n1.0 rgb/0.png\n2.0\n");
  ExpectInputError([&] { TumSequence s(folder()); }, "rgb.txt:3: expected 'timestamp path'");
  WriteText("rgb.txt", "1.0 rgb/0.png\nabc rgb/1.png\n");
  ExpectInputError([&] { TumSequence s(folder()); }, "rgb.txt:2: not a number");
  WriteText("rgb.txt", "1.0 rgb/0.png\n1.0 rgb/1.png\n");
  ExpectInputError([&] { TumSequence s(folder()); }, "rgb.txt:2: duplicate timestamp");
  WriteText("rgb.txt", "1.0 rgb/0.png\n-2e12 rgb/1.png\n");
  ExpectInputError([&] { TumSequence s(folder()); },
                   "rgb.txt:2: timestamp '-2e12' is beyond +-1e12 s");
  WriteText("rgb.txt", good_rgb);
  WriteText("depth.txt", "2.0 depth/0.png\n\n1.0 depth/1.png\n");
  ExpectInputError([&] { TumSequence s(folder()); }, "depth.txt:3: timestamps are not increasing");
  WriteText("depth.txt", "5.0 depth/0.png\n6.0 depth/1.png\n");
  ExpectInputError([&] { TumSequence s(folder()); }, "no rgb/depth associations found");
  fs::remove(dir_ / "depth.txt");
  ExpectInputError([&] { TumSequence s(folder()); }, "depth list not found");
}

TEST_F(TumSequenceTest, BadAssociationsAndGroundTruth) {
  WriteSequence();
  TumSequenceOptions options;
  options.associations_file = "missing.txt";
  ExpectInputError([&] { TumSequence s(folder(), options); }, "associations file not found");
  options.associations_file = "assoc.txt";
  WriteText("assoc.txt", "1.0 rgb/0.png 1.0\n");
  ExpectInputError([&] { TumSequence s(folder(), options); },
                   "assoc.txt:1: expected 'rgb_timestamp");
  WriteText("assoc.txt", "# nothing\n");
  ExpectInputError([&] { TumSequence s(folder(), options); }, "no associations");
  WriteText("assoc.txt", "2.0 rgb/0.png 2.0 depth/0.png\n1.0 rgb/1.png 1.0 depth/1.png\n");
  ExpectInputError([&] { TumSequence s(folder(), options); },
                   "assoc.txt:2: timestamps are not increasing");
  WriteText("groundtruth.txt", "1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n2.0 5 0 0 0 0 0 1\n");
  EXPECT_EQ(TumSequence(folder()).ground_truth().back().world_from_cam.translation.x(), 5.0);
  WriteText("groundtruth.txt", "1.0 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 0 1\n");
  ExpectInputError([&] { TumSequence s(folder()); },
                   "groundtruth.txt:2: timestamps are not increasing");
  WriteText("groundtruth.txt", "1.0 0 0 0 0 0 0 1\n2.0 0 0 0\n");
  ExpectInputError([&] { TumSequence s(folder()); }, "groundtruth.txt:2: expected 8 values");
  // Timestamps are seconds: 1e250 would fail only when the trajectory is written, after the run.
  WriteText("groundtruth.txt", "1.0 0 0 0 0 0 0 1\n1e250 0 0 0 0 0 0 1\n");
  ExpectInputError([&] { TumSequence s(folder()); },
                   "groundtruth.txt:2: timestamp '1e250' is beyond +-1e12 s");
  TumSequenceOptions no_gt;
  no_gt.load_ground_truth = false;
  EXPECT_FALSE(TumSequence(folder(), no_gt).HasGroundTruth());
}

TEST_F(TumSequenceTest, BadImages) {
  WriteSequence();
  TumSequence seq(folder());
  fs::remove(dir_ / "rgb/0.png");
  ExpectInputError([&] { seq.Frame(0); }, "rgb image not found: " + (dir_ / "rgb/0.png").string());
  TumSequenceOptions check;
  check.check_images_exist = true;
  ExpectInputError([&] { TumSequence s(folder(), check); }, "rgb image not found");

  WriteText("rgb/0.png", "this is not a png");
  ExpectInputError([&] { seq.Frame(0); }, "rgb image cannot be read");
  fs::remove(dir_ / "depth/1.png");
  ExpectInputError([&] { seq.Frame(1); }, "depth image not found");

  cv::Mat depth8(kHeight, kWidth, CV_8UC1, cv::Scalar(7));
  ASSERT_TRUE(cv::imwrite((dir_ / "depth/1.png").string(), depth8));
  ExpectInputError([&] { seq.Frame(1); }, "depth image must be 16-bit single channel");
  cv::Mat depth16c3(kHeight, kWidth, CV_16UC3, cv::Scalar(7, 7, 7));
  ASSERT_TRUE(cv::imwrite((dir_ / "depth/1.png").string(), depth16c3));
  ExpectInputError([&] { seq.Frame(1); }, "is 16U with 3 channel(s)");
  WriteText("depth/1.png", "garbage");
  ExpectInputError([&] { seq.Frame(1); }, "depth image cannot be read");

  // A PNG cut short is named as such (libpng would print its own line first); one with a few
  // bytes after its end chunk still reads.
  cv::Mat depth(kHeight, kWidth, CV_16UC1, cv::Scalar(5000));
  std::vector<uchar> png;
  ASSERT_TRUE(cv::imencode(".png", depth, png));
  WriteText("depth/1.png", std::string(png.begin(), png.end() - 12));
  ExpectInputError([&] { seq.Frame(1); }, "depth image is truncated (a PNG without its end): " +
                                              (dir_ / "depth/1.png").string());
  WriteText("depth/1.png", std::string(png.begin(), png.end()) + "trailing");
  EXPECT_EQ(seq.Frame(1).depth_m.at<float>(0, 0), 1.0f);

  cv::Mat small(kHeight - 1, kWidth, CV_16UC1, cv::Scalar(5000));
  ASSERT_TRUE(cv::imwrite((dir_ / "depth/2.png").string(), small));
  ExpectInputError([&] { seq.Frame(2); }, "depth image size 8x5 differs from rgb image size 8x6");
  ExpectInputError([&] { seq.Frame(3); }, "out of range");
}

TEST_F(TumSequenceTest, OptionsValidate) {
  WriteSequence();
  TumSequenceOptions options;
  options.depth_factor = 0.0;
  ExpectInputError([&] { TumSequence s(folder(), options); }, "depth_factor must be > 0");
  options = {};
  options.max_difference_s = -1.0;
  ExpectInputError([&] { TumSequence s(folder(), options); }, "max_difference_s must be > 0");
}

// ---------------------------------------------------------------------------------------------
// Real TUM data (shared, read-only).

const std::string kTumDir = DYNORB_SHARED_DIR "/data/tum/";

size_t CountDataLines(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  size_t n = 0;
  while (std::getline(in, line)) {
    const size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#') ++n;
  }
  return n;
}

TEST(TumRealData, Frame0OfWalkingXyzLoadsWithPlausibleDepth) {
  const std::string folder = kTumDir + "rgbd_dataset_freiburg3_walking_xyz_frame0";
  if (!fs::is_directory(folder)) GTEST_SKIP() << "shared TUM data not available at " << folder;
  TumSequenceOptions via_file;
  via_file.associations_file = "associations.txt";
  for (const TumSequenceOptions& options : {TumSequenceOptions{}, via_file}) {
    TumSequence seq(folder, options);
    ASSERT_EQ(seq.size(), 1u);
    const RgbdFrame frame = seq.Frame(0);
    EXPECT_DOUBLE_EQ(frame.timestamp_s, 1341846313.592026);
    EXPECT_DOUBLE_EQ(frame.depth_timestamp_s, 1341846313.592088);
    ASSERT_EQ(frame.rgb.type(), CV_8UC3);
    ASSERT_EQ(frame.rgb.size(), cv::Size(640, 480));
    ASSERT_EQ(frame.depth_m.size(), cv::Size(640, 480));
    std::vector<float> valid;
    for (int v = 0; v < frame.depth_m.rows; ++v) {
      for (int u = 0; u < frame.depth_m.cols; ++u) {
        const float d = frame.depth_m.at<float>(v, u);
        ASSERT_GE(d, 0.0f);
        if (d > 0.0f) valid.push_back(d);
      }
    }
    const double valid_fraction = static_cast<double>(valid.size()) / (640.0 * 480.0);
    std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
    const float median = valid[valid.size() / 2];
    const float max_depth = *std::max_element(valid.begin(), valid.end());
    // Measured on this frame: 70.6 % valid, median 2.618 m. A Kinect frame has holes but is
    // mostly valid; metres (not mm or raw units) put the median in a room-sized range.
    EXPECT_GT(valid_fraction, 0.5);
    EXPECT_LT(valid_fraction, 0.95);
    EXPECT_GT(median, 0.5f);
    EXPECT_LT(median, 5.0f);
    EXPECT_LT(max_depth, 10.0f);  // a 16-bit/5000 misread would give up to 13 m; mm would give 65 m
    RecordProperty("valid_fraction", std::to_string(valid_fraction));
    RecordProperty("median_depth_m", std::to_string(median));
  }
}

TEST(TumRealData, AssociationFilesOfFourSequences) {
  const std::vector<std::pair<std::string, size_t>> sequences = {
      {"rgbd_dataset_freiburg3_walking_xyz", 827},
      {"rgbd_dataset_freiburg3_walking_static", 717},
      {"rgbd_dataset_freiburg3_walking_rpy", 866},
      {"rgbd_dataset_freiburg3_sitting_static", 680}};
  if (!fs::is_directory(kTumDir)) GTEST_SKIP() << "shared TUM data not available at " << kTumDir;
  for (const auto& [name, expected_frames] : sequences) {
    const std::string folder = kTumDir + name;
    const std::string assoc = folder + "/associations.txt";
    TumSequenceOptions options;
    options.associations_file = "associations.txt";
    const TumSequence seq(folder, options);
    EXPECT_EQ(seq.size(), CountDataLines(assoc)) << name;
    EXPECT_EQ(seq.size(), expected_frames) << name;
    // Ground truth is read too and covers the frames. walking_static's official file repeats one
    // stamp (1341846251.4587); the reader keeps the last pose of the pair.
    ASSERT_TRUE(seq.HasGroundTruth()) << name;
    const size_t gt_lines = CountDataLines(folder + "/groundtruth.txt");
    EXPECT_EQ(seq.ground_truth().size(),
              name == "rgbd_dataset_freiburg3_walking_static" ? gt_lines - 1 : gt_lines)
        << name;
    EXPECT_LT(seq.ground_truth().front().timestamp_s, seq.entries().front().rgb_timestamp_s + 1.0);
    EXPECT_GT(seq.ground_truth().back().timestamp_s, seq.entries().back().rgb_timestamp_s - 1.0);
    // Re-associating the real stamps with associate.py's rule reproduces the file's pairs.
    std::vector<StampedPath> rgb, depth;
    for (const AssociatedPair& p : seq.entries()) {
      rgb.push_back({p.rgb_timestamp_s, p.rgb_path});
      depth.push_back({p.depth_timestamp_s, p.depth_path});
    }
    const std::vector<AssociatedPair> again = AssociateImageLists(rgb, depth);
    ASSERT_EQ(again.size(), seq.size()) << name;
    for (size_t i = 0; i < again.size(); ++i) {
      ASSERT_EQ(again[i].depth_path, seq.entries()[i].depth_path) << name << " frame " << i;
    }
  }
}

}  // namespace
}  // namespace dynorb
