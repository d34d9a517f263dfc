// The two renderers of a PlotCanvas: PNG through OpenCV, SVG as text.
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "dynorb/eval/plot.h"
#include "dynorb/eval/text_format.h"

namespace dynorb {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kHersheyCapHeightPx = 22.0;  // cap height of FONT_HERSHEY_SIMPLEX at scale 1
constexpr int kSubpixelBits = 4;              // fixed-point drawing for sub-pixel accuracy
constexpr double kSubpixel = 1 << kSubpixelBits;

cv::Scalar Bgr(PlotColor c) { return cv::Scalar(c.b, c.g, c.r); }
cv::Point Fixed(double x, double y) {
  return cv::Point(static_cast<int>(std::lround(x * kSubpixel)),
                   static_cast<int>(std::lround(y * kSubpixel)));
}
int Thickness(double px) { return std::max(1, static_cast<int>(std::lround(px))); }

std::string Hex(PlotColor c) {
  char buf[8];
  std::snprintf(buf, sizeof(buf), "#%02x%02x%02x", c.r, c.g, c.b);
  return buf;
}


void DrawLayer(const PlotLayer& canvas, cv::Mat& image) {
  for (const PlotRect& r : canvas.rects) {
    const cv::Point a = Fixed(r.x, r.y), b = Fixed(r.x + r.width, r.y + r.height);
    if (r.filled) cv::rectangle(image, a, b, Bgr(r.fill), cv::FILLED, cv::LINE_8, kSubpixelBits);
    if (r.stroke_px > 0.0) {
      if (r.width == 0.0 || r.height == 0.0) {
        cv::line(image, a, b, Bgr(r.stroke), Thickness(r.stroke_px), cv::LINE_AA, kSubpixelBits);
      } else {
        cv::rectangle(image, a, b, Bgr(r.stroke), Thickness(r.stroke_px), cv::LINE_AA,
                      kSubpixelBits);
      }
    }
  }
  for (const PlotPolyline& line : canvas.lines) {
    std::vector<cv::Point> points;
    points.reserve(line.points_px.size());
    for (const Eigen::Vector2d& p : line.points_px) points.push_back(Fixed(p.x(), p.y()));
    cv::polylines(image, points, false, Bgr(line.color), Thickness(line.width_px), cv::LINE_AA,
                  kSubpixelBits);
  }
  for (const PlotText& t : canvas.texts) {
    const double scale = t.height_px / kHersheyCapHeightPx;
    const int thickness = t.height_px >= 16.0 ? 2 : 1;
    int baseline = 0;
    const cv::Size size = cv::getTextSize(t.text, kFont, scale, thickness, &baseline);
    double x = t.anchor_px.x();
    if (t.align == PlotTextAlign::kCenter) x -= 0.5 * size.width;
    if (t.align == PlotTextAlign::kRight) x -= size.width;
    const double y = t.anchor_px.y() + 0.5 * size.height;
    cv::putText(image, t.text,
                cv::Point(static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y))),
                kFont, scale, Bgr(t.color), thickness, cv::LINE_AA);
  }
}

void WriteSvgLayer(const PlotLayer& canvas, std::ostringstream& svg) {
  for (const PlotRect& r : canvas.rects) {
    if (r.width == 0.0 || r.height == 0.0) {
      svg << "<line x1=\"" << r.x << "\" y1=\"" << r.y << "\" x2=\"" << r.x + r.width << "\" y2=\""
          << r.y + r.height << "\" stroke=\"" << Hex(r.stroke) << "\" stroke-width=\""
          << r.stroke_px << "\"/>\n";
      continue;
    }
    svg << "<rect x=\"" << r.x << "\" y=\"" << r.y << "\" width=\"" << r.width << "\" height=\""
        << r.height << "\" fill=\"" << (r.filled ? Hex(r.fill) : "none") << "\" stroke=\""
        << (r.stroke_px > 0.0 ? Hex(r.stroke) : "none") << "\" stroke-width=\"" << r.stroke_px
        << "\"/>\n";
  }
  for (const PlotPolyline& line : canvas.lines) {
    svg << "<polyline fill=\"none\" stroke=\"" << Hex(line.color) << "\" stroke-width=\""
        << line.width_px << "\" stroke-linejoin=\"round\" points=\"";
    char buf[64];
    for (const Eigen::Vector2d& p : line.points_px) {
      std::snprintf(buf, sizeof(buf), "%.1f,%.1f ", p.x(), p.y());
      svg << buf;
    }
    svg << "\"/>\n";
  }
  for (const PlotText& t : canvas.texts) {
    const char* anchor = t.align == PlotTextAlign::kLeft     ? "start"
                         : t.align == PlotTextAlign::kCenter ? "middle"
                                                             : "end";
    svg << "<text x=\"" << t.anchor_px.x() << "\" y=\"" << t.anchor_px.y()
        << "\" font-family=\"sans-serif\" "
        << "font-size=\"" << t.height_px / 0.72 << "\" dominant-baseline=\"central\" text-anchor=\""
        << anchor << "\" fill=\"" << Hex(t.color) << "\">" << EscapeXml(t.text) << "</text>\n";
  }
}

}  // namespace

std::vector<unsigned char> RenderPlotPng(const PlotCanvas& canvas) {
  cv::Mat image(canvas.height_px, canvas.width_px, CV_8UC3, cv::Scalar(255, 255, 255));
  DrawLayer(canvas.base, image);
  DrawLayer(canvas.overlay, image);
  std::vector<unsigned char> bytes;
  cv::imencode(".png", image, bytes);
  return bytes;
}

std::string RenderPlotSvg(const PlotCanvas& canvas) {
  std::ostringstream svg;
  svg.precision(6);
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << canvas.width_px << "\" height=\""
      << canvas.height_px << "\" viewBox=\"0 0 " << canvas.width_px << " " << canvas.height_px
      << "\">\n";
  WriteSvgLayer(canvas.base, svg);
  WriteSvgLayer(canvas.overlay, svg);
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace dynorb
