#include "dynorb/eval/report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>

#include "dynorb/eval/plot.h"
#include "dynorb/eval/trajectory_generator.h"

namespace dynorb {
namespace {

struct Fixture {
  TrajectoryPair pair;
  EvalResult result;
};

Fixture Make(double drop_fraction = 0.02) {
  TrajectoryPairOptions o;
  o.duration_s = 20.0;
  o.drop_fraction = drop_fraction;
  Fixture f;
  f.pair = GenerateTrajectoryPair(o);
  f.result = EvaluateTrajectories(f.pair.groundtruth, f.pair.estimate, EvalOptions());
  return f;
}

TEST(Report, TableHasAllRowsAndDefinitions) {
  const Fixture f = Make();
  const std::string table = FormatReportTable(f.result, {"gt.txt", "est.txt"});
  for (const char* needle :
       {"ground truth  gt.txt (601 poses)", "ATE [m]", "RPE trans [m/s]", "RPE rot [deg/s]",
        "coverage", "alignment     se3", "evaluate_rpe.py --fixed_delta --delta 1 --delta_unit s",
        "rmse", "median"}) {
    EXPECT_NE(table.find(needle), std::string::npos) << needle << "\n" << table;
  }
  EXPECT_EQ(table.find("warning"), std::string::npos) << table;
}

TEST(Report, JsonMatchesResult) {
  const Fixture f = Make();
  const nlohmann::json j = nlohmann::json::parse(FormatReportJson(f.result, {"gt.txt", "est.txt"}));
  EXPECT_EQ(j["schema"], "dynorb.eval/1");
  EXPECT_EQ(j["ate_m"]["count"], f.result.ate.stats.count);
  EXPECT_DOUBLE_EQ(j["ate_m"]["rmse"].get<double>(), f.result.ate.stats.rmse);
  EXPECT_DOUBLE_EQ(j["rpe"]["trans_m"]["rmse"].get<double>(), f.result.rpe.trans_m.rmse);
  EXPECT_DOUBLE_EQ(j["coverage"]["fraction"].get<double>(), f.result.coverage.fraction);
  EXPECT_EQ(j["alignment"]["mode"], "se3");
  EXPECT_NE(j["coverage"]["definition"].get<std::string>().find("+-0.05 s"), std::string::npos);
  EXPECT_EQ(j["inputs"]["estimate_poses"], f.result.est_poses);
  EXPECT_TRUE(j["warnings"].empty());
}

// A file path need not be UTF-8 (Latin-1 names on Linux): the JSON replaces the bad bytes with
// U+FFFD instead of throwing nlohmann's type_error 316.
TEST(Report, JsonTakesANonUtf8Label) {
  const Fixture f = Make();
  std::string text;
  ASSERT_NO_THROW(text = FormatReportJson(f.result, {"gt_caf\xE9.txt", "est.txt"}));
  const nlohmann::json j = nlohmann::json::parse(text);
  EXPECT_EQ(j["inputs"]["groundtruth"], "gt_caf\xEF\xBF\xBD.txt");
  EXPECT_EQ(j["inputs"]["estimate"], "est.txt");
}

TEST(Report, LowCoverageWarnsInTable) {
  Fixture f = Make(0.0);
  Trajectory est;
  for (size_t k = 0; k < f.pair.estimate.size(); ++k) {
    if (k < 200 || k > 300) est.push_back(f.pair.estimate[k]);
  }
  const EvalResult r = EvaluateTrajectories(f.pair.groundtruth, est, EvalOptions());
  EXPECT_NE(FormatReportTable(r, {"g", "e"}).find("warning: coverage"), std::string::npos);
}

TEST(Plot, NiceTicks) {
  const std::vector<double> t = NiceTicks(-0.37, 1.21, 6);
  ASSERT_FALSE(t.empty());
  EXPECT_NEAR(t.front(), -0.2, 1e-12);
  EXPECT_NEAR(t[1] - t[0], 0.2, 1e-12);
  EXPECT_LE(t.back(), 1.21);
  EXPECT_TRUE(NiceTicks(1.0, 1.0, 5).empty());
}

TEST(Plot, PngAndSvgDrawTheSameLayout) {
  const Fixture f = Make();
  const PlotCanvas canvas = LayoutEvalFigure(f.pair.groundtruth, f.pair.estimate, f.result);
  EXPECT_GE(canvas.base.lines.size(), 5u);  // 2 x (gt + estimate pieces) + error + rmse
  EXPECT_GE(canvas.base.texts.size(), 20u);
  EXPECT_EQ(canvas.overlay.rects.size(), 3u);  // one legend per panel
  for (const PlotPolyline& line : canvas.base.lines) {
    for (const Eigen::Vector2d& p : line.points_px) {
      EXPECT_TRUE(p.x() >= 0 && p.x() <= canvas.width_px && p.y() >= 0 &&
                  p.y() <= canvas.height_px);
    }
  }
  const std::vector<unsigned char> png = RenderPlotPng(canvas);
  const cv::Mat image = cv::imdecode(png, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, canvas.width_px);
  EXPECT_EQ(image.rows, canvas.height_px);
  const std::string svg = RenderPlotSvg(canvas);
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  size_t polylines = 0;
  for (size_t at = svg.find("<polyline"); at != std::string::npos;
       at = svg.find("<polyline", at + 1))
    ++polylines;
  EXPECT_EQ(polylines, canvas.base.lines.size() + canvas.overlay.lines.size());
  EXPECT_NE(svg.find("top view (x-y)"), std::string::npos);
}

// One ground-truth pose (possible with --align none): the error panel's time axis spans 0 s and
// used to map every point to NaN.
TEST(Plot, OneGroundTruthPoseGivesNoNan) {
  Trajectory gt(1), est(1);
  gt[0].timestamp_s = est[0].timestamp_s = 5.0;
  gt[0].world_from_cam.translation = Eigen::Vector3d(1.0, 2.0, 3.0);
  est[0].world_from_cam.translation = Eigen::Vector3d(1.1, 2.0, 3.0);
  EvalOptions options;
  options.alignment = AlignmentMode::kNone;
  const EvalResult result = EvaluateTrajectories(gt, est, options);
  const PlotCanvas canvas = LayoutEvalFigure(gt, est, result);
  for (const PlotLayer* layer : {&canvas.base, &canvas.overlay}) {
    for (const PlotPolyline& line : layer->lines) {
      for (const Eigen::Vector2d& p : line.points_px) {
        EXPECT_TRUE(p.allFinite());
        EXPECT_TRUE(p.x() >= 0 && p.x() <= canvas.width_px && p.y() >= 0 &&
                    p.y() <= canvas.height_px);
      }
    }
    for (const PlotRect& r : layer->rects) {
      EXPECT_TRUE(std::isfinite(r.x) && std::isfinite(r.y) && std::isfinite(r.width) &&
                  std::isfinite(r.height));
    }
    for (const PlotText& t : layer->texts) EXPECT_TRUE(t.anchor_px.allFinite()) << t.text;
  }
  const std::string svg = RenderPlotSvg(canvas);
  // "nan"/"inf" as a printed number, not inside a word ("dominant-baseline").
  EXPECT_FALSE(std::regex_search(svg, std::regex("(^|[^a-z])-?(nan|inf)([^a-z]|$)")));
  EXPECT_FALSE(RenderPlotPng(canvas).empty());
}

TEST(TrajectoryGenerator, DeterministicAndAsSpecified) {
  TrajectoryPairOptions o;
  o.seed = 42;
  o.duration_s = 10.0;
  o.noise_m = 0.0;
  o.drift_m_per_s = 0.0;
  o.scale = 0.5;
  const TrajectoryPair a = GenerateTrajectoryPair(o), b = GenerateTrajectoryPair(o);
  ASSERT_EQ(a.estimate.size(), b.estimate.size());
  for (size_t k = 0; k < a.estimate.size(); ++k) {
    EXPECT_EQ(a.estimate[k].timestamp_s, b.estimate[k].timestamp_s);
    EXPECT_EQ(a.estimate[k].world_from_cam.translation, b.estimate[k].world_from_cam.translation);
  }
  EXPECT_EQ(a.groundtruth.size(), 301u);
  EXPECT_LT(a.estimate.size(), a.groundtruth.size());
  EvalOptions eo;
  eo.alignment = AlignmentMode::kSim3;
  const EvalResult r = EvaluateTrajectories(a.groundtruth, a.estimate, eo);
  EXPECT_NEAR(r.ate.gt_from_est.scale, 2.0, 1e-9);  // no noise: exact
  EXPECT_LT(r.ate.stats.rmse, 1e-9);
  EXPECT_GT(r.ate.stats.count, 280);
}

}  // namespace
}  // namespace dynorb
