// Darknet cfg/weights layout and class pruning on a constructed model (exact values), loaded by
// OpenCV DNN: the pruned network's outputs are the full network's kept columns.
#include "dynorb/dynamic/darknet_model.h"

#include <cstdint>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/dnn.hpp>

#include "dynorb/core/error.h"
#include "dynorb/core/test_expect_error.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;
using testing::ExpectInputError;

// A 32 x 32 network: a 3x3 batch-normalised convolution (4 filters, stride 2), a 1x1 head of
// 2 anchors x (5 + 3 classes) = 16 filters, one [yolo] layer.
std::string TinyCfg(int head_filters = 16) {
  return "[net]\nwidth=32\nheight=32\nchannels=3\n\n"
         "[convolutional]\nbatch_normalize=1\nfilters=4\nsize=3\nstride=2\npad=1\nactivation="
         "leaky\n\n"
         "# the head\n[convolutional]\nsize=1\nstride=1\npad=1\nfilters=" +
         std::to_string(head_filters) +
         "\nactivation=linear\n\n"
         "[yolo]\nmask = 0,1\nanchors = 4,6, 10,12\nclasses=3\nnum=2\n";
}

// Header (version 0.2.0, 8-byte seen) and floats 0.01 * i (variances positive).
std::vector<float> WriteTinyModel(const fs::path& dir, const std::string& cfg, size_t floats) {
  fs::create_directories(dir);
  std::ofstream(dir / "tiny.cfg") << cfg;
  std::vector<float> values(floats);
  for (size_t i = 0; i < floats; ++i) values[i] = 0.01f * static_cast<float>(i % 97) - 0.3f;
  for (size_t i = 12; i < 16; ++i) values[i] = 0.5f + 0.1f * static_cast<float>(i);  // BN variances
  std::ofstream out(dir / "tiny.weights", std::ios::binary);
  const int32_t version[3] = {0, 2, 0};
  const int64_t seen = 0;
  out.write(reinterpret_cast<const char*>(version), sizeof(version));
  out.write(reinterpret_cast<const char*>(&seen), sizeof(seen));
  out.write(reinterpret_cast<const char*>(values.data()),
            static_cast<std::streamsize>(floats * sizeof(float)));
  return values;
}

// conv 1: 4 x (bias, scale, mean, var) + 4 x 3 x 3 x 3; head: 16 biases + 16 x 4 kernels.
constexpr size_t kConv1Floats = 16 + 108;
constexpr size_t kHeadFloats = 16 + 64;

TEST(DarknetModel, LayoutAndExpectedSize) {
  const fs::path dir = fs::temp_directory_path() / "dynorb_darknet_layout";
  WriteTinyModel(dir, TinyCfg(), kConv1Floats + kHeadFloats);
  const std::string cfg = (dir / "tiny.cfg").string();
  const auto convs = DarknetConvolutions(ReadDarknetCfg(cfg), cfg);
  ASSERT_EQ(convs.size(), 2u);
  EXPECT_EQ(convs[0].Floats(), kConv1Floats);
  EXPECT_EQ(convs[1].in_channels, 4);
  EXPECT_EQ(convs[1].Floats(), kHeadFloats);
  const size_t header = DarknetWeightsHeaderBytes((dir / "tiny.weights").string());
  EXPECT_EQ(header, 20u);
  EXPECT_EQ(DarknetExpectedWeightBytes(cfg, header), fs::file_size(dir / "tiny.weights"));
  fs::remove_all(dir);
}

TEST(DarknetModel, PrunedHeadKeepsBoxObjectnessAndTheKeptClasses) {
  const fs::path dir = fs::temp_directory_path() / "dynorb_darknet_prune";
  const std::vector<float> values = WriteTinyModel(dir, TinyCfg(), kConv1Floats + kHeadFloats);
  const std::string cfg = (dir / "tiny.cfg").string(), weights = (dir / "tiny.weights").string();
  const DarknetBuffers pruned = PruneDarknetClasses(cfg, weights, {0, 2}, 3, "tiny.names");
  EXPECT_NE(pruned.cfg.find("filters=14\n"), std::string::npos);  // 2 x (5 + 2)
  EXPECT_NE(pruned.cfg.find("classes=2\n"), std::string::npos);
  EXPECT_NE(pruned.cfg.find("filters=4\n"), std::string::npos);  // the first layer untouched
  ASSERT_EQ(pruned.weights.size(), 20 + (kConv1Floats + 14 + 14 * 4) * sizeof(float));
  const float* w = reinterpret_cast<const float*>(pruned.weights.data() + 20);
  for (size_t i = 0; i < kConv1Floats; ++i) ASSERT_EQ(w[i], values[i]);
  // Head outputs kept: anchor 0 -> 0..4, 5, 7; anchor 1 -> 8..12, 13, 15.
  const int kept[14] = {0, 1, 2, 3, 4, 5, 7, 8, 9, 10, 11, 12, 13, 15};
  const float* head = values.data() + kConv1Floats;
  for (int k = 0; k < 14; ++k) {
    EXPECT_EQ(w[kConv1Floats + k], head[kept[k]]) << "bias " << k;
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(w[kConv1Floats + 14 + 4 * k + c], head[16 + 4 * kept[k] + c]) << "kernel " << k;
    }
  }

  // OpenCV DNN runs both; the pruned rows are the full rows' box, objectness and kept classes.
  cv::dnn::Net full = cv::dnn::readNetFromDarknet(cfg, weights);
  cv::dnn::Net cut = cv::dnn::readNetFromDarknet(pruned.cfg.data(), pruned.cfg.size(),
                                                 pruned.weights.data(), pruned.weights.size());
  cv::Mat image(32, 32, CV_32FC3);
  cv::randu(image, 0.f, 1.f);
  const cv::Mat blob = cv::dnn::blobFromImage(image);
  full.setInput(blob);
  cut.setInput(blob);
  const cv::Mat a = full.forward().clone(), b = cut.forward().clone();
  ASSERT_EQ(a.rows, b.rows);
  ASSERT_EQ(a.cols, 8);
  ASSERT_EQ(b.cols, 7);
  double worst = 0.0, largest_score = 0.0;
  for (int r = 0; r < a.rows; ++r) {
    const int columns[7] = {0, 1, 2, 3, 4, 5, 7};
    for (int c = 0; c < 7; ++c) {
      worst = std::max(
          worst, std::abs(static_cast<double>(a.at<float>(r, columns[c]) - b.at<float>(r, c))));
    }
    largest_score = std::max(largest_score, static_cast<double>(a.at<float>(r, 7)));
  }
  EXPECT_LT(worst, 1e-5);
  EXPECT_GT(largest_score, 0.0) << "the comparison must see non-zero class scores";
  fs::remove_all(dir);
}

TEST(DarknetModel, PruningBadInputIsAClearError) {
  const fs::path dir = fs::temp_directory_path() / "dynorb_darknet_prune_bad";
  WriteTinyModel(dir, TinyCfg(), kConv1Floats + kHeadFloats);
  const std::string cfg = (dir / "tiny.cfg").string(), weights = (dir / "tiny.weights").string();
  auto prune = [&](const std::vector<int>& keep, int names = 3) {
    PruneDarknetClasses(cfg, weights, keep, names, "tiny.names");
  };
  ExpectInputError([&] { prune({3}); }, "head has 3 classes");
  ExpectInputError([&] { prune({-1, 0}); }, "must not be negative");
  ExpectInputError([&] { prune({2, 1}); }, "strictly increasing");
  ExpectInputError([&] { prune({}); }, "at least one class");
  // A names file of another length than the heads' classes would shift every class id.
  ExpectInputError([&] { prune({0}, 4); }, "predicts 3 classes, but tiny.names names 4");
  // A head whose convolution does not have anchors x (5 + classes) filters.
  WriteTinyModel(dir, TinyCfg(12), kConv1Floats + 12 + 48);
  ExpectInputError([&] { prune({0}); }, "cannot prune");
  // Weights of another size than the cfg describes.
  WriteTinyModel(dir, TinyCfg(), kConv1Floats);
  ExpectInputError([&] { prune({0}); }, "does not match");
  fs::remove_all(dir);
}

// OpenCV zeroes [yolo] class scores below the head's thresh (0.2 by default): the rewritten cfg
// lets lower scores through and changes nothing else.
TEST(DarknetModel, YoloThresholdLineLetsLowScoresThrough) {
  const std::string two_heads =
      "[net]\nwidth=32\n[yolo]\nthresh = 0.5\nclasses=3\n[route]\nlayers=-1\n[yolo]\nclasses=3";
  EXPECT_EQ(DarknetCfgWithYoloThreshold(two_heads, 0.05),
            "[net]\nwidth=32\n[yolo]\nthresh = 0.5\nclasses=3\nthresh=0.05\n[route]\nlayers=-1\n"
            "[yolo]\nclasses=3\nthresh=0.05\n");
  EXPECT_EQ(DarknetCfgWithYoloThreshold("[net]\nwidth=32\n# [yolo]\n", 0.1),
            "[net]\nwidth=32\n# [yolo]\n");

  const fs::path dir = fs::temp_directory_path() / "dynorb_darknet_thresh";
  WriteTinyModel(dir, TinyCfg(), kConv1Floats + kHeadFloats);
  const std::string cfg = (dir / "tiny.cfg").string(), weights = (dir / "tiny.weights").string();
  DarknetBuffers model = ReadDarknetModel(cfg, weights);
  ASSERT_EQ(model.cfg, TinyCfg());
  ASSERT_EQ(model.weights.size(), fs::file_size(weights));
  cv::Mat image(32, 32, CV_32FC3);
  cv::randu(image, 0.f, 1.f);
  auto class_scores = [&](const std::string& text) {
    cv::dnn::Net net = cv::dnn::readNetFromDarknet(text.data(), text.size(), model.weights.data(),
                                                   model.weights.size());
    net.setInput(cv::dnn::blobFromImage(image));
    const cv::Mat out = net.forward().clone();
    return out.colRange(5, out.cols).clone();
  };
  // This tiny network's class scores lie in 0.23..0.27: a thresh line of 0.25 zeroes some that
  // the default floor (0.2) and a line of 0.01 both keep, so the line is what OpenCV applies.
  const cv::Mat floor = class_scores(model.cfg);
  const cv::Mat low = class_scores(DarknetCfgWithYoloThreshold(model.cfg, 0.01));
  const cv::Mat high = class_scores(DarknetCfgWithYoloThreshold(model.cfg, 0.25));
  int zeroed = 0, kept = 0;
  for (int r = 0; r < low.rows; ++r) {
    for (int c = 0; c < low.cols; ++c) {
      const float l = low.at<float>(r, c), h = high.at<float>(r, c);
      EXPECT_EQ(floor.at<float>(r, c), l);
      if (l > 0.f && l < 0.25f) {
        EXPECT_EQ(h, 0.f);
        ++zeroed;
      } else {
        EXPECT_EQ(h, l);
        ++kept;
      }
    }
  }
  EXPECT_GT(zeroed, 0);
  EXPECT_GT(kept, 0);
  fs::remove_all(dir);
}

// Sizes that overflowed int arithmetic (found with UBSan) are refused or handled.
TEST(DarknetModel, HugeCountsAreRefused) {
  const fs::path dir = fs::temp_directory_path() / "dynorb_darknet_huge";
  fs::create_directories(dir);
  std::ofstream(dir / "huge.cfg")
      << "[net]\nchannels=3\n[convolutional]\nfilters=2000000000\nsize=1\n[route]\nlayers=-1,-1\n";
  const std::string huge = (dir / "huge.cfg").string();
  ExpectInputError([&] { DarknetConvolutions(ReadDarknetCfg(huge), huge); },
                   "filters must be 1..1048576");
  std::ofstream(dir / "wide.cfg") << "[net]\nchannels=3\n[convolutional]\nfilters=1000000\nsize=1\n"
                                     "[route]\nlayers=-1,-1\n";
  const std::string wide = (dir / "wide.cfg").string();
  ExpectInputError([&] { DarknetConvolutions(ReadDarknetCfg(wide), wide); },
                   "joins more than 1048576");
  {
    std::ofstream out(dir / "v.weights", std::ios::binary);
    const int32_t version[3] = {0x7fffffff, 0x7fffffff, 0};
    out.write(reinterpret_cast<const char*>(version), sizeof(version));
  }
  EXPECT_EQ(DarknetWeightsHeaderBytes((dir / "v.weights").string()), 16u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dynorb
