// Trajectory figure of `dynorb eval --plot`: one layout, two renderers.
//
// LayoutEvalFigure() computes the whole figure as a list of primitives in pixel coordinates
// (origin top-left, y down): a title, a top view (x-y) and a side view (x-z) of the ground truth
// and the aligned estimate with equal axis scales, and the ATE translational error over time,
// each panel with tick labels in metres/seconds and a legend. RenderPlotPng() (OpenCV) and
// RenderPlotSvg() (plain text) draw the same primitives, so both files show the same figure.
// Pure functions, thread-safe.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "dynorb/core/trajectory.h"
#include "dynorb/eval/evaluate.h"

namespace dynorb {

struct PlotColor {
  uint8_t r = 0, g = 0, b = 0;
};

struct PlotPolyline {
  std::vector<Eigen::Vector2d> points_px;
  PlotColor color;
  double width_px = 1.0;
};

enum class PlotTextAlign { kLeft, kCenter, kRight };

struct PlotText {
  Eigen::Vector2d anchor_px = Eigen::Vector2d::Zero();  // vertical centre of the text line
  std::string text;                                     // ASCII only (OpenCV's Hershey fonts)
  double height_px = 14.0;                              // cap height
  PlotColor color;
  PlotTextAlign align = PlotTextAlign::kLeft;
};

struct PlotRect {
  double x = 0, y = 0, width = 0, height = 0;
  PlotColor stroke;
  double stroke_px = 1.0;  // 0: no outline
  bool filled = false;
  PlotColor fill;
};

// Drawn in this order: rects, polylines, texts.
struct PlotLayer {
  std::vector<PlotRect> rects;
  std::vector<PlotPolyline> lines;
  std::vector<PlotText> texts;
};

// `base` (axes, data, labels) is drawn first, then `overlay` (legends) on top.
struct PlotCanvas {
  int width_px = 1600;
  int height_px = 1100;
  PlotLayer base;
  PlotLayer overlay;
};

PlotCanvas LayoutEvalFigure(const Trajectory& gt, const Trajectory& est, const EvalResult& result);

// PNG file bytes (OpenCV imgproc drawing + imgcodecs encoding).
std::vector<unsigned char> RenderPlotPng(const PlotCanvas& canvas);
// SVG document text.
std::string RenderPlotSvg(const PlotCanvas& canvas);

// "Nice" tick values (1, 2, 5 x 10^k steps) covering [lo, hi]; about `target` ticks.
std::vector<double> NiceTicks(double lo, double hi, int target);

}  // namespace dynorb
