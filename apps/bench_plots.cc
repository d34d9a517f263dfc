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
#include "dynorb/io/point_cloud_io.h"
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

bool WriteMapView(const std::string& run_dir, const std::string& path, const std::string& title) {
  const fs::path ply = fs::path(run_dir) / "map.ply",
                 keyframes = fs::path(run_dir) / "keyframes.txt";
  if (!fs::exists(ply) || !fs::exists(keyframes)) return false;
  try {
    const PointCloud cloud = ReadPlyPointCloud(ply.string());
    const Trajectory kfs = ReadTumTrajectory(keyframes.string());
    if (kfs.empty()) return false;
    const std::vector<uint8_t>* ids = nullptr;
    for (const auto& [name, values] : cloud.flags) {
      if (name == "dynamic_object_id") ids = &values;
    }
    // The virtual camera: the first keyframe's, moved 1 m back, with a wide field of view.
    Rigid3d view_from_world = kfs.front().world_from_cam.Inverse();
    view_from_world.translation += Eigen::Vector3d(0.0, 0.0, 1.0);
    const int width = 640, height = 480;
    const double f = 320.0;
    struct Dot {
      double depth;
      Eigen::Vector2d direction;  // x/z, y/z in the view
      cv::Point pixel;
      cv::Vec3b rgb;
      bool dynamic;
    };
    std::vector<Dot> in_front;
    std::vector<double> xs, ys;
    for (size_t i = 0; i < cloud.points.size(); ++i) {
      const Eigen::Vector3d p = view_from_world * cloud.points[i].cast<double>();
      if (p.z() < 0.2) continue;
      in_front.push_back({p.z(), p.head<2>() / p.z(), cv::Point(), cloud.rgb[i],
                          ids != nullptr && (*ids)[i] != 0});
      xs.push_back(in_front.back().direction.x());
      ys.push_back(in_front.back().direction.y());
    }
    // Centred on the median direction of the points in front of the camera.
    auto median = [](std::vector<double> v) {
      if (v.empty()) return 0.0;
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      return v[v.size() / 2];
    };
    const double cx = width / 2.0 - f * median(xs), cy = height / 2.0 - f * median(ys);
    std::vector<Dot> dots;
    for (Dot& d : in_front) {
      d.pixel = cv::Point(static_cast<int>(f * d.direction.x() + cx),
                          static_cast<int>(f * d.direction.y() + cy));
      if (d.pixel.x < -3 || d.pixel.y < -3 || d.pixel.x > width + 3 || d.pixel.y > height + 3)
        continue;
      dots.push_back(d);
    }
    // Far points first, so that near ones are drawn over them.
    std::sort(dots.begin(), dots.end(),
              [](const Dot& a, const Dot& b) { return a.depth > b.depth; });
    cv::Mat colours(height, width, CV_8UC3, cv::Scalar(255, 255, 255)), truth = colours.clone();
    int on_objects = 0;
    for (const Dot& d : dots) {
      const int radius = d.depth < 2.0 ? 3 : 2;
      cv::circle(colours, d.pixel, radius, cv::Scalar(d.rgb[2], d.rgb[1], d.rgb[0]), cv::FILLED,
                 cv::LINE_AA);
      cv::circle(truth, d.pixel, radius,
                 d.dynamic ? cv::Scalar(0, 0, 230) : cv::Scalar(150, 150, 150), cv::FILLED,
                 cv::LINE_AA);
      on_objects += d.dynamic ? 1 : 0;
    }
    auto label = [](cv::Mat* image, const std::string& text, int row) {
      cv::putText(*image, text, cv::Point(8, 20 * row), cv::FONT_HERSHEY_SIMPLEX, 0.5,
                  cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    };
    label(&colours, title + ": " + std::to_string(cloud.points.size()) + " landmarks", 1);
    label(&truth,
          ids == nullptr
              ? std::string("no ground-truth masks")
              : "red: made on dynamic objects (" + std::to_string(on_objects) + " in view)",
          1);
    cv::Mat both;
    cv::hconcat(colours, truth, both);
    std::vector<unsigned char> png;
    if (!cv::imencode(".png", both, png)) return false;
    WriteFileAtomically(path, std::string(png.begin(), png.end()));
    return true;
  } catch (const std::exception&) {
    return false;  // an unreadable map: the report shows the run without its picture
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
