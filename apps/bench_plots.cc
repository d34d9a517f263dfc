#include "bench_plots.h"

#include <algorithm>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "dynorb/eval/evaluate.h"
#include "dynorb/eval/plot.h"
#include "dynorb/io/atomic_file.h"
#include "dynorb/io/trajectory_io.h"

namespace dynorb {

namespace fs = std::filesystem;

bool WriteTrajectoryPlot(const std::string& dataset, const std::string& run_dir,
                         const std::string& stem, const std::string& title) {
  const fs::path gt_path = fs::path(dataset) / "groundtruth.txt";
  const fs::path est_path = fs::path(run_dir) / "trajectory.txt";
  if (!fs::exists(gt_path) || !fs::exists(est_path)) return false;
  try {
    const Trajectory est = ReadTumTrajectory(est_path.string());
    if (est.size() < 3) return false;
    const double begin = est.front().timestamp_s - 0.05, end = est.back().timestamp_s + 0.05;
    Trajectory gt;
    for (const StampedPose& p : ReadTumGroundTruth(gt_path.string())) {
      if (p.timestamp_s >= begin && p.timestamp_s <= end) gt.push_back(p);
    }
    const EvalResult result = EvaluateTrajectories(gt, est, EvalOptions());
    PlotCanvas canvas = LayoutEvalFigure(gt, est, result);
    PlotText label;
    label.anchor_px = Eigen::Vector2d(canvas.width_px - 20.0, canvas.height_px - 16.0);  // bottom right
    label.text = title;
    label.align = PlotTextAlign::kRight;
    label.color = PlotColor{90, 90, 90};
    canvas.overlay.texts.push_back(label);
    const std::vector<unsigned char> png = RenderPlotPng(canvas);
    WriteFileAtomically(stem + ".png", std::string(png.begin(), png.end()));
    WriteFileAtomically(stem + ".svg", RenderPlotSvg(canvas));
    return true;
  } catch (const std::exception&) {
    return false;  // e.g. no overlap with the ground truth: the report shows the run without a plot
  }
}

bool WriteKeypointStrip(const std::string& overlay_dir, const std::string& path, int count) {
  std::vector<fs::path> images;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(overlay_dir, ec)) {
    if (entry.path().extension() == ".png") images.push_back(entry.path());
  }
  if (images.empty()) return false;
  std::sort(images.begin(), images.end());
  count = std::min<int>(count, static_cast<int>(images.size()));
  std::vector<cv::Mat> tiles;
  for (int k = 0; k < count; ++k) {
    // Evenly spaced over the sequence, skipping the first tenth (initialisation).
    const size_t first = images.size() / 10;
    const size_t index = first + (images.size() - 1 - first) * (k + 1) / count;
    cv::Mat image = cv::imread(images[index].string(), cv::IMREAD_COLOR);
    if (image.empty()) continue;
    cv::Mat half;
    cv::resize(image, half, cv::Size(image.cols / 2, image.rows / 2), 0, 0, cv::INTER_AREA);
    cv::putText(half, "frame " + images[index].stem().string(), cv::Point(8, 20),
                cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
    cv::putText(half, "frame " + images[index].stem().string(), cv::Point(8, 20),
                cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    if (!tiles.empty() && half.size() != tiles.front().size())
      cv::resize(half, half, tiles.front().size());
    tiles.push_back(half);
  }
  if (tiles.empty()) return false;
  cv::Mat strip;
  cv::hconcat(tiles, strip);
  std::vector<unsigned char> png;
  if (!cv::imencode(".png", strip, png)) return false;
  WriteFileAtomically(path, std::string(png.begin(), png.end()));
  return true;
}

}  // namespace dynorb
