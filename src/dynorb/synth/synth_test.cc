#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "dynorb/core/error.h"
#include "dynorb/io/config.h"
#include "dynorb/io/trajectory_io.h"
#include "dynorb/io/tum_sequence.h"
#include "dynorb/synth/sequence_writer.h"
#include "dynorb/synth/synthesizer.h"

namespace dynorb::synth {
namespace {
namespace fs = std::filesystem;

SynthOptions Options(bool noise, bool twin = false) {
  SynthOptions o;
  o.preset = "walking_xyz";
  o.seed = 7;
  o.frames = 4;
  o.noise = noise;
  o.static_twin = twin;
  return o;
}

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("dynorb_synth_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

// Shared sequences (building the office takes a moment).
class SynthSequence : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    clean_ = new SequenceSynth(Options(false));
    twin_ = new SequenceSynth(Options(false, true));
  }
  static void TearDownTestSuite() {
    delete clean_;
    delete twin_;
  }
  static SequenceSynth* clean_;
  static SequenceSynth* twin_;
};
SequenceSynth* SynthSequence::clean_ = nullptr;
SequenceSynth* SynthSequence::twin_ = nullptr;

// Mean absolute grey-level difference between frame b and frame a warped into b with b's true
// depth and the given relative pose, over static pixels with depth.
double WarpError(const SynthFrame& a, const SynthFrame& b, const Rigid3d& a_from_b,
                 const PinholeCamera& cam) {
  cv::Mat grey_a, grey_b;
  cv::cvtColor(a.rgb, grey_a, cv::COLOR_BGR2GRAY);
  cv::cvtColor(b.rgb, grey_b, cv::COLOR_BGR2GRAY);
  double sum = 0;
  int n = 0;
  for (int v = 0; v < cam.height; v += 2) {
    for (int u = 0; u < cam.width; u += 2) {
      const float z = b.depth_m.at<float>(v, u);
      if (z <= 0.0f || z > 4.5f || b.mask.at<uchar>(v, u)) continue;
      const Eigen::Vector3d p = a_from_b * cam.Unproject(Eigen::Vector2d(u, v), z);
      if (p.z() < 0.1) continue;
      const Eigen::Vector2d q = cam.Project(p);
      if (q.x() < 1 || q.y() < 1 || q.x() > cam.width - 2 || q.y() > cam.height - 2) continue;
      const int qu = static_cast<int>(std::lround(q.x())),
                qv = static_cast<int>(std::lround(q.y()));
      if (a.mask.at<uchar>(qv, qu)) continue;
      cv::Mat patch;
      cv::getRectSubPix(grey_a, cv::Size(1, 1),
                        cv::Point2f(static_cast<float>(q.x()), static_cast<float>(q.y())), patch,
                        CV_32F);
      sum += std::abs(patch.at<float>(0, 0) - grey_b.at<uchar>(v, u));
      ++n;
    }
  }
  EXPECT_GT(n, 20000);
  return sum / std::max(1, n);
}

TEST_F(SynthSequence, GroundTruthPosesAndDepthExplainTheImages) {
  auto renderer = clean_->MakeRenderer();
  const SynthFrame f0 = clean_->RenderFrame(0, renderer.get());
  const SynthFrame f1 = clean_->RenderFrame(1, renderer.get());
  const Rigid3d a_from_b = f0.world_from_cam.Inverse() * f1.world_from_cam;
  const double error = WarpError(f0, f1, a_from_b, clean_->camera());
  // A 1 cm / 0.3 degree error in the relative pose makes the warp clearly worse.
  const Rigid3d wrong =
      a_from_b * Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.005, Eigen::Vector3d::UnitY())),
                         Eigen::Vector3d(0.01, 0, 0));
  const double wrong_error = WarpError(f0, f1, wrong, clean_->camera());
  std::cout << "warp error: true poses " << error << ", perturbed " << wrong_error
            << " grey levels\n";
  EXPECT_LT(error, 3.0);
  EXPECT_GT(wrong_error, 1.5 * error);
}

TEST_F(SynthSequence, MasksExactlyCoverTheMovingObjectsAndTheTwinMatchesElsewhere) {
  auto renderer = clean_->MakeRenderer();
  for (int k : {0, 3}) {
    const SynthFrame dyn = clean_->RenderFrame(k, renderer.get());
    const SynthFrame stat = twin_->RenderFrame(k, renderer.get());
    EXPECT_EQ(cv::countNonZero(stat.mask), 0);
    const cv::Mat moving = dyn.mask > 0;
    ASSERT_GT(cv::countNonZero(moving), 2000) << "a person should be in view at frame " << k;
    cv::Mat rgb_diff, depth_diff;
    cv::absdiff(dyn.rgb, stat.rgb, rgb_diff);
    cv::transform(rgb_diff, rgb_diff, cv::Matx13f(1, 1, 1));
    const cv::Mat differs = (rgb_diff > 0) | (dyn.depth_u16 != stat.depth_u16);
    // Outside the mask the images are identical; inside, (nearly) every pixel shows the object.
    EXPECT_EQ(cv::countNonZero(differs & ~moving), 0);
    EXPECT_GT(cv::countNonZero(differs & moving), 0.97 * cv::countNonZero(moving));
    // The depth at mask pixels is the object's: nearer than the static scene.
    EXPECT_EQ(cv::countNonZero((dyn.depth_m > stat.depth_m + 1e-4f) & moving), 0);
  }
}

TEST_F(SynthSequence, ImagesHavePlentyOfWellSpreadOrbFeatures) {
  SynthOptions o = Options(true);
  SequenceSynth noisy(o);
  auto renderer = noisy.MakeRenderer();
  const SynthFrame f = noisy.RenderFrame(0, renderer.get());
  cv::Mat grey;
  cv::cvtColor(f.rgb, grey, cv::COLOR_BGR2GRAY);
  std::vector<cv::KeyPoint> keypoints;
  cv::ORB::create(2000)->detect(grey, keypoints);
  cv::Mat cells = cv::Mat::zeros(6, 8, CV_8U);
  for (const cv::KeyPoint& k : keypoints)
    cells.at<uchar>(static_cast<int>(k.pt.y / 80), static_cast<int>(k.pt.x / 80)) = 1;
  std::cout << "ORB keypoints: " << keypoints.size() << ", cells covered "
            << cv::countNonZero(cells) << "/48\n";
  EXPECT_GE(keypoints.size(), 1000u);
  EXPECT_GE(cv::countNonZero(cells),
            33);  // >= 2/3 of the image (white panels, desk tops are plain)
}

TEST_F(SynthSequence, FramesAreDeterministic) {
  SequenceSynth again(Options(false));
  auto r1 = clean_->MakeRenderer();
  auto r2 = again.MakeRenderer();
  const SynthFrame a = clean_->RenderFrame(2, r1.get());
  const SynthFrame b = again.RenderFrame(2, r2.get());
  EXPECT_EQ(cv::norm(a.rgb, b.rgb, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.depth_u16, b.depth_u16, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.mask, b.mask, cv::NORM_INF), 0.0);
}

TEST(Synthesize, WritesATumSequenceThatTheLoaderReadsBack) {
  const fs::path dir = TempDir("roundtrip");
  SynthOptions o = Options(true);
  o.frames = 3;
  o.out_dir = dir.string();
  o.threads = 2;
  const SynthReport report = Synthesize(o);
  EXPECT_EQ(report.frames, 3);
  for (const char* f : {"rgb.txt", "depth.txt", "groundtruth.txt", "camera.yaml", "scene.yaml",
                        "associations.txt", "masks.txt", "objects.txt"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  TumSequence sequence(dir.string());
  ASSERT_EQ(sequence.size(), 3u);
  ASSERT_TRUE(sequence.HasGroundTruth());
  ASSERT_EQ(sequence.ground_truth().size(), 3u);
  SequenceSynth synth(o);
  auto renderer = synth.MakeRenderer();
  for (size_t i = 0; i < sequence.size(); ++i) {
    const RgbdFrame frame = sequence.Frame(i);
    const SynthFrame expected = synth.RenderFrame(static_cast<int>(i), renderer.get());
    EXPECT_EQ(frame.rgb.size(), cv::Size(640, 480));
    EXPECT_EQ(cv::norm(frame.rgb, expected.rgb, cv::NORM_INF), 0.0);  // bit-identical regeneration
    EXPECT_NEAR(frame.timestamp_s, expected.time.rgb_ts, 1e-6);
    EXPECT_GT(frame.depth_timestamp_s, frame.timestamp_s);
    EXPECT_LT(frame.depth_timestamp_s - frame.timestamp_s, 0.005);
    const StampedPose& gt = sequence.ground_truth()[i];
    EXPECT_NEAR(gt.timestamp_s, frame.timestamp_s, 1e-6);
    EXPECT_LT((gt.world_from_cam.translation - expected.world_from_cam.translation).norm(), 1e-8);
    // Depth: Kinect-like noise around the true depth, missing where the sensor sees nothing.
    int valid = 0, close = 0;
    for (int v = 0; v < 480; v += 4)
      for (int u = 0; u < 640; u += 4) {
        const float measured = frame.depth_m.at<float>(v, u),
                    truth = expected.depth_m.at<float>(v, u);
        if (measured <= 0) continue;
        ++valid;
        if (std::abs(measured - truth) < 0.01f + 0.01f * truth * truth) ++close;
        EXPECT_LE(measured, 4.6f);
      }
    EXPECT_GT(valid, 0.5 * 160 * 120);
    EXPECT_GT(close, 0.97 * valid);
    const cv::Mat mask =
        cv::imread((dir / "masks" / (SequenceWriter::Stamp(frame.timestamp_s) + ".png")).string(),
                   cv::IMREAD_UNCHANGED);
    ASSERT_EQ(mask.type(), CV_8UC1);
    EXPECT_EQ(cv::norm(mask, expected.mask, cv::NORM_INF), 0.0);
  }
  std::ifstream yaml((dir / "camera.yaml").string());
  std::string first;
  std::getline(yaml, first);
  EXPECT_EQ(first, "%YAML:1.0");
  // The settings a run reads from it: ORB-SLAM2's keys, ThDepth 50 (synth_version 4).
  const SystemConfig config = LoadSystemConfig((dir / "camera.yaml").string());
  EXPECT_EQ(config.camera.bf, 40.0);
  EXPECT_EQ(config.camera.th_depth, 50.0);
  EXPECT_EQ(config.camera.depth_map_factor, 5000.0);
  EXPECT_EQ(config.orb.n_features, 1000);
  fs::remove_all(dir);
}

TEST(Synthesize, RejectsBadInputWithAClearError) {
  const fs::path dir = TempDir("bad");
  auto expect_error = [](SynthOptions o, const std::string& fragment) {
    try {
      Synthesize(o);
      ADD_FAILURE() << "no error for " << fragment;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  SynthOptions o = Options(false);
  o.out_dir = dir.string();
  SynthOptions bad = o;
  bad.preset = "walking_sideways";
  expect_error(bad, "unknown preset");
  bad = o;
  bad.texture_dir = "/nonexistent/textures";
  bad.texture_dir_explicit = true;
  expect_error(bad, "texture directory not found");
  bad = o;
  bad.people_dir = "/nonexistent/people";
  expect_error(bad, "people directory not found");
  bad = o;
  bad.trajectory_file = "/nonexistent/groundtruth.txt";
  expect_error(bad, "trajectory file not found");
  bad = o;
  bad.out_dir = "/proc/dynorb_synth_test/out";
  expect_error(bad, "cannot create output directory");
  bad = o;
  bad.texture_dir = fs::temp_directory_path().string();  // exists, but has no photographs
  bad.texture_dir_explicit = true;
  expect_error(bad, "texture file missing");
  EXPECT_FALSE(fs::exists(dir)) << "a failed run must not leave an output directory behind";
  fs::create_directories(dir);
  std::ofstream(dir / "keep.txt") << "x";
  expect_error(o, "not empty");
  EXPECT_TRUE(fs::exists(dir / "keep.txt"));
  // A people directory without cut-outs.
  bad = o;
  bad.out_dir = (dir / "sub").string();
  bad.people_dir = dir.string();
  expect_error(bad, "no RGBA *.png cut-outs");
  cv::imwrite((dir / "ghost.png").string(), cv::Mat(8, 4, CV_8UC4, cv::Scalar(200, 100, 50, 20)));
  expect_error(bad,
               "person cut-out has no opaque pixel (alpha > 127): " + (dir / "ghost.png").string());
  fs::remove_all(dir);
}

TEST(CameraPath, ReexpressesARealTrajectoryFromTheStartPose) {
  Trajectory gt;
  for (int i = 0; i < 5; ++i) {
    const Eigen::Quaterniond q(
        Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d(0.2, 0.9, 0.1).normalized()));
    gt.push_back({100.0 + 0.1 * i, Rigid3d(q, Eigen::Vector3d(0.3 * i, -1.0 + 0.05 * i * i, 1.4))});
  }
  const Rigid3d start = LookAt(Eigen::Vector3d(3, 1, 1.4), Eigen::Vector3d(3, 4, 0.8));
  const CameraPath path(gt, start);
  EXPECT_NEAR(path.duration_s(), 0.4, 1e-12);
  EXPECT_LT((path.WorldFromCam(0.0).translation - start.translation).norm(), 1e-12);
  // Relative motion between any two times is preserved; in between, slerp + linear.
  const Rigid3d rel_synth = path.WorldFromCam(0.1).Inverse() * path.WorldFromCam(0.3);
  const Rigid3d rel_real = gt[1].world_from_cam.Inverse() * gt[3].world_from_cam;
  EXPECT_LT((rel_synth.translation - rel_real.translation).norm(), 1e-9);
  EXPECT_LT(RotationAngleRad(rel_synth.rotation * rel_real.rotation.conjugate()), 1e-9);
  const Rigid3d mid =
      start * gt[0].world_from_cam.Inverse() *
      Rigid3d(gt[1].world_from_cam.rotation.slerp(0.5, gt[2].world_from_cam.rotation),
              0.5 * (gt[1].world_from_cam.translation + gt[2].world_from_cam.translation));
  EXPECT_LT((path.WorldFromCam(0.15).translation - mid.translation).norm(), 1e-9);
}

TEST(CameraPath, PresetsAreSmoothAndStayInTheRoom) {
  for (const Preset& preset : Presets()) {
    const CameraPath path(preset, Eigen::Vector3d(3, 1, 1.4), Eigen::Vector3d(2.8, 4.4, 0.85), 3);
    double max_step = 0;
    for (double t = 0; t < preset.duration_s; t += 1.0 / 30.0) {
      const Rigid3d a = path.WorldFromCam(t), b = path.WorldFromCam(t + 1.0 / 30.0);
      max_step = std::max(max_step, (a.translation - b.translation).norm());
      EXPECT_GT(a.translation.x(), 0.3);
      EXPECT_LT(a.translation.x(), 5.7);
      EXPECT_GT(a.translation.y(), 0.2);
      EXPECT_LT(a.translation.y(), 2.0);
    }
    EXPECT_LT(max_step, 0.05) << preset.name;  // < 1.5 m/s hand-held
  }
}

}  // namespace
}  // namespace dynorb::synth
