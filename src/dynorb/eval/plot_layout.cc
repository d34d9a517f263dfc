// LayoutEvalFigure: the figure geometry shared by the PNG and SVG renderers.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "dynorb/eval/plot.h"
#include "dynorb/eval/report.h"

namespace dynorb {
namespace {

constexpr PlotColor kBlack{0, 0, 0};
constexpr PlotColor kGrid{225, 225, 225};
constexpr PlotColor kText{30, 30, 30};
constexpr PlotColor kGroundTruth{40, 40, 40};
constexpr PlotColor kEstimate{31, 119, 180};
constexpr PlotColor kError{214, 39, 40};
constexpr PlotColor kRmse{120, 120, 120};
constexpr PlotColor kWhite{255, 255, 255};

template <typename... Args>
std::string Format(const char* fmt, Args... args) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), fmt, args...);
  return buf;
}

struct Range {
  double lo = 0.0, hi = 0.0;
  void Include(double v) {
    if (empty) {
      lo = hi = v;
      empty = false;
    } else {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  void Pad(double fraction, double min_extent) {
    double extent = std::max(hi - lo, min_extent);
    const double mid = 0.5 * (lo + hi);
    extent *= 1.0 + 2.0 * fraction;
    lo = mid - 0.5 * extent;
    hi = mid + 0.5 * extent;
  }
  bool empty = true;
};

// Maps data coordinates of one panel to pixels.
struct Panel {
  double x = 0, y = 0, width = 0, height = 0;  // pixel box
  Range u, v;                                  // data ranges (horizontal, vertical)
  Eigen::Vector2d ToPx(double du, double dv) const {
    return {x + (du - u.lo) / (u.hi - u.lo) * width,
            y + height - (dv - v.lo) / (v.hi - v.lo) * height};
  }
};

// Widens one range so that one data unit spans the same pixels on both axes.
void EqualAspect(Panel& p) {
  const double su = (p.u.hi - p.u.lo) / p.width, sv = (p.v.hi - p.v.lo) / p.height;
  Range& r = su > sv ? p.v : p.u;
  const double target = std::max(su, sv) * (su > sv ? p.height : p.width);
  const double mid = 0.5 * (r.lo + r.hi);
  r.lo = mid - 0.5 * target;
  r.hi = mid + 0.5 * target;
}

std::string TickLabel(double value, double step) {
  const int decimals = std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  if (std::abs(value) < 0.5 * step) value = 0.0;
  return Format("%.*f", decimals, value);
}

// Adds a polyline, dropping points closer than 0.5 px to the previous kept point.
void AddLine(PlotLayer& c, const std::vector<Eigen::Vector2d>& pts, PlotColor color, double width) {
  PlotPolyline line;
  line.color = color;
  line.width_px = width;
  for (const Eigen::Vector2d& p : pts) {
    if (line.points_px.empty() || (p - line.points_px.back()).norm() >= 0.5)
      line.points_px.push_back(p);
  }
  if (line.points_px.size() == 1)
    line.points_px.push_back(line.points_px.front() + Eigen::Vector2d(0.5, 0));
  if (!line.points_px.empty()) c.lines.push_back(std::move(line));
}

void AddText(PlotLayer& c, double x, double y, const std::string& text, double h,
             PlotTextAlign align, PlotColor color = kText) {
  PlotText t;
  t.anchor_px = {x, y};
  t.text = text;
  t.height_px = h;
  t.align = align;
  t.color = color;
  c.texts.push_back(std::move(t));
}

void DrawAxes(PlotLayer& c, const Panel& p, const std::string& title, const std::string& u_label,
              const std::string& v_label) {
  PlotRect frame{p.x, p.y, p.width, p.height, kBlack, 1.0, true, kWhite};
  c.rects.push_back(frame);
  const std::vector<double> u_ticks = NiceTicks(p.u.lo, p.u.hi, 7);
  const double u_step = u_ticks.size() > 1 ? u_ticks[1] - u_ticks[0] : 1.0;
  for (double t : u_ticks) {
    const double px = p.ToPx(t, p.v.lo).x();
    c.rects.push_back({px, p.y, 0.0, p.height, kGrid, 1.0, false, {}});
    c.rects.push_back({px, p.y + p.height, 0.0, 6.0, kBlack, 1.0, false, {}});
    AddText(c, px, p.y + p.height + 18, TickLabel(t, u_step), 11, PlotTextAlign::kCenter);
  }
  const std::vector<double> v_ticks = NiceTicks(p.v.lo, p.v.hi, 6);
  const double v_step = v_ticks.size() > 1 ? v_ticks[1] - v_ticks[0] : 1.0;
  for (double t : v_ticks) {
    const double py = p.ToPx(p.u.lo, t).y();
    c.rects.push_back({p.x, py, p.width, 0.0, kGrid, 1.0, false, {}});
    c.rects.push_back({p.x - 6.0, py, 6.0, 0.0, kBlack, 1.0, false, {}});
    AddText(c, p.x - 10, py, TickLabel(t, v_step), 11, PlotTextAlign::kRight);
  }
  // Frame outline again on top of the grid lines.
  c.rects.push_back({p.x, p.y, p.width, p.height, kBlack, 1.0, false, {}});
  AddText(c, p.x + 0.5 * p.width, p.y - 16, title, 14, PlotTextAlign::kCenter, kBlack);
  AddText(c, p.x + 0.5 * p.width, p.y + p.height + 42, u_label, 12, PlotTextAlign::kCenter);
  AddText(c, p.x - 10, p.y - 16, v_label, 12, PlotTextAlign::kRight);
}

struct LegendEntry {
  std::string label;
  PlotColor color;
  double width;
};

// Puts the legend into the panel corner that hides the fewest data points.
void DrawLegend(PlotLayer& c, const Panel& p, const std::vector<Eigen::Vector2d>& data_px,
                const std::vector<LegendEntry>& entries) {
  double max_chars = 0;
  for (const LegendEntry& e : entries) max_chars = std::max<double>(max_chars, e.label.size());
  const double w = 66 + 9.0 * max_chars, h = 10 + 22.0 * entries.size();
  double x = 0, y = 0;
  size_t best_hidden = std::numeric_limits<size_t>::max();
  for (int corner = 0; corner < 4; ++corner) {
    const double cx = corner % 2 == 0 ? p.x + 10 : p.x + p.width - 10 - w;
    const double cy = corner < 2 ? p.y + 10 : p.y + p.height - 10 - h;
    size_t hidden = 0;
    for (const Eigen::Vector2d& q : data_px) {
      hidden += q.x() >= cx - 5 && q.x() <= cx + w + 5 && q.y() >= cy - 5 && q.y() <= cy + h + 5;
    }
    if (hidden < best_hidden) {
      best_hidden = hidden;
      x = cx;
      y = cy;
    }
  }
  c.rects.push_back({x, y, w, h, kRmse, 1.0, true, kWhite});
  for (size_t k = 0; k < entries.size(); ++k) {
    const double row = y + 16 + 22.0 * k;
    c.lines.push_back({{{x + 8, row}, {x + 40, row}}, entries[k].color, entries[k].width + 1.0});
    AddText(c, x + 48, row, entries[k].label, 11, PlotTextAlign::kLeft);
  }
}

}  // namespace

std::vector<double> NiceTicks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi) || target < 1) return ticks;
  const double raw = (hi - lo) / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * magnitude;
    if (step >= 0.75 * raw) break;
  }
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step) ticks.push_back(t);
  return ticks;
}

PlotCanvas LayoutEvalFigure(const Trajectory& gt, const Trajectory& est, const EvalResult& result) {
  PlotCanvas canvas;
  PlotLayer& c = canvas.base;
  c.rects.push_back(
      {0, 0, double(canvas.width_px), double(canvas.height_px), kWhite, 0.0, true, kWhite});
  const Similarity3d& gt_from_est = result.ate.gt_from_est;

  // Series in data coordinates. The estimate line breaks where its stamps jump (dropped frames).
  std::vector<Eigen::Vector3d> gt_xyz, est_xyz;
  std::vector<bool> est_break;  // true: do not connect to the previous estimate pose
  for (const StampedPose& p : gt) gt_xyz.push_back(p.world_from_cam.translation);
  const double max_step_s = 2.0 * result.options.coverage_window_s;
  for (size_t k = 0; k < est.size(); ++k) {
    est_xyz.push_back(gt_from_est * est[k].world_from_cam.translation);
    est_break.push_back(k == 0 || est[k].timestamp_s - est[k - 1].timestamp_s > max_step_s);
  }

  const std::string title = Format(
      "ATE RMSE %.4f m (%s, %d pairs)   RPE %s   coverage %.1f%%", result.ate.stats.rmse,
      ToString(result.ate.mode).c_str(), result.ate.stats.count,
      result.rpe.trans_m.count > 0 ? Format("%.4f m / %.2f deg per %g s", result.rpe.trans_m.rmse,
                                            result.rpe.rot_deg.rmse, result.options.rpe_delta_s)
                                         .c_str()
                                   : "n/a",
      100.0 * result.coverage.fraction);
  AddText(c, 0.5 * canvas.width_px, 28, title, 17, PlotTextAlign::kCenter, kBlack);

  const int views[2][2] = {{0, 1}, {0, 2}};  // (x, y) top view, (x, z) side view
  const char* names[3] = {"x [m]", "y [m]", "z [m]"};
  for (int v = 0; v < 2; ++v) {
    Panel p;
    p.x = v == 0 ? 100 : 900;
    p.y = 90;
    p.width = 640;
    p.height = 560;
    const int a = views[v][0], b = views[v][1];
    for (const auto* series : {&gt_xyz, &est_xyz}) {
      for (const Eigen::Vector3d& q : *series) {
        p.u.Include(q[a]);
        p.v.Include(q[b]);
      }
    }
    p.u.Pad(0.05, 0.1);
    p.v.Pad(0.05, 0.1);
    EqualAspect(p);
    DrawAxes(c, p, v == 0 ? "top view (x-y)" : "side view (x-z)", names[a], names[b]);
    std::vector<Eigen::Vector2d> pts, all_px;
    for (const Eigen::Vector3d& q : gt_xyz) pts.push_back(p.ToPx(q[a], q[b]));
    AddLine(c, pts, kGroundTruth, 1.5);
    all_px = pts;
    pts.clear();
    for (size_t k = 0; k < est_xyz.size(); ++k) {
      if (est_break[k] && !pts.empty()) {
        AddLine(c, pts, kEstimate, 1.5);
        pts.clear();
      }
      pts.push_back(p.ToPx(est_xyz[k][a], est_xyz[k][b]));
      all_px.push_back(pts.back());
    }
    AddLine(c, pts, kEstimate, 1.5);
    DrawLegend(canvas.overlay, p, all_px,
               {{"ground truth", kGroundTruth, 1.5},
                {"estimate (" + ToString(result.ate.mode) + "-aligned)", kEstimate, 1.5}});
  }

  // Error over time.
  Panel e;
  e.x = 100;
  e.y = 770;
  e.width = 1440;
  e.height = 250;
  const double t0 = gt.front().timestamp_s;
  e.u.Include(0.0);
  e.u.Include(gt.back().timestamp_s - t0);
  e.u.Pad(0.0, 0.1);  // one ground-truth pose: zero span, centred on 0 (lo = 0 otherwise)
  e.v.Include(0.0);
  for (double err : result.ate.errors_m) e.v.Include(err);
  e.v.hi = std::max(e.v.hi, 1e-3) * 1.08;
  DrawAxes(c, e, "ATE translational error over time", "time since first ground-truth pose [s]",
           "error [m]");
  std::vector<Eigen::Vector2d> pts, all_px;
  double previous_s = -1e300;
  for (size_t k = 0; k < result.ate.pairs.size(); ++k) {
    const double s = gt[result.ate.pairs[k].gt].timestamp_s - t0;
    if (s - previous_s > max_step_s && !pts.empty()) {
      AddLine(c, pts, kError, 1.5);
      pts.clear();
    }
    previous_s = s;
    pts.push_back(e.ToPx(s, result.ate.errors_m[k]));
    all_px.push_back(pts.back());
  }
  AddLine(c, pts, kError, 1.5);
  const double rmse_y = e.ToPx(0.0, result.ate.stats.rmse).y();
  c.lines.push_back({{{e.x, rmse_y}, {e.x + e.width, rmse_y}}, kRmse, 1.0});
  DrawLegend(
      canvas.overlay, e, all_px,
      {{"ATE error", kError, 1.5}, {Format("RMSE %.4f m", result.ate.stats.rmse), kRmse, 1.0}});
  return canvas;
}

}  // namespace dynorb
