#include "dynorb/dynamic/detector_decode.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <opencv2/imgproc.hpp>

namespace dynorb {
namespace {

float Sigmoid(float x) { return 1.f / (1.f + std::exp(-x)); }

// Best class of a score row among the allowed ones (all when `allowed` is empty): (index, score);
// (-1, 0) when none is allowed.
std::pair<int, float> BestClass(const float* scores, int num_classes,
                                const std::vector<bool>& allowed) {
  if (allowed.empty()) {
    const float* best = std::max_element(scores, scores + num_classes);
    return {static_cast<int>(best - scores), *best};
  }
  CV_Assert(static_cast<int>(allowed.size()) == num_classes);
  std::pair<int, float> best{-1, 0.f};
  for (int c = 0; c < num_classes; ++c) {
    if (allowed[c] && (best.first < 0 || scores[c] > best.second)) best = {c, scores[c]};
  }
  return best;
}

Detection FromCenter(float cx, float cy, float w, float h, int class_id, float score) {
  Detection d;
  d.box = cv::Rect2f(cx - 0.5f * w, cy - 0.5f * h, w, h);
  d.class_id = class_id;
  d.score = score;
  return d;
}

// Total element count of an n-dimensional Mat.
size_t Elements(const cv::Mat& m) { return m.total() * static_cast<size_t>(m.channels()); }

}  // namespace

ResizeTransform StretchTransform(cv::Size image, cv::Size net) {
  ResizeTransform t;
  t.scale_x = static_cast<double>(net.width) / image.width;
  t.scale_y = static_cast<double>(net.height) / image.height;
  t.net_size = net;
  t.resized_size = net;
  return t;
}

ResizeTransform LetterboxTransform(cv::Size image, cv::Size net, bool centered) {
  ResizeTransform t;
  const double scale = std::min(static_cast<double>(net.width) / image.width,
                                static_cast<double>(net.height) / image.height);
  t.scale_x = t.scale_y = scale;
  // At least one pixel either way (a 2000 x 2 image would round to 0 rows, which cv::resize
  // refuses).
  t.resized_size =
      cv::Size(std::clamp(static_cast<int>(std::lround(image.width * scale)), 1, net.width),
               std::clamp(static_cast<int>(std::lround(image.height * scale)), 1, net.height));
  if (centered) {
    t.pad_x = (net.width - t.resized_size.width) / 2;
    t.pad_y = (net.height - t.resized_size.height) / 2;
  }
  t.net_size = net;
  return t;
}

cv::Mat ApplyResize(const cv::Mat& bgr, const ResizeTransform& t, const cv::Scalar& pad_value) {
  if (t.resized_size == t.net_size && t.pad_x == 0 && t.pad_y == 0) {
    cv::Mat out;
    cv::resize(bgr, out, t.net_size, 0, 0, cv::INTER_LINEAR);
    return out;
  }
  cv::Mat out(t.net_size, CV_8UC3, pad_value);
  const cv::Rect roi(static_cast<int>(t.pad_x), static_cast<int>(t.pad_y), t.resized_size.width,
                     t.resized_size.height);
  cv::Mat target = out(roi);
  cv::resize(bgr, target, t.resized_size, 0, 0, cv::INTER_LINEAR);
  return out;
}

std::vector<Detection> MapToImage(const std::vector<Detection>& net_boxes, const ResizeTransform& t,
                                  cv::Size image) {
  std::vector<Detection> out;
  out.reserve(net_boxes.size());
  const cv::Rect2f frame(0.f, 0.f, static_cast<float>(image.width), static_cast<float>(image.height));
  for (const Detection& d : net_boxes) {
    Detection m = d;
    m.box.x = static_cast<float>((d.box.x - t.pad_x) / t.scale_x);
    m.box.y = static_cast<float>((d.box.y - t.pad_y) / t.scale_y);
    m.box.width = static_cast<float>(d.box.width / t.scale_x);
    m.box.height = static_cast<float>(d.box.height / t.scale_y);
    m.box &= frame;
    if (m.box.width > 0.f && m.box.height > 0.f) out.push_back(m);
  }
  return out;
}

std::vector<Detection> DecodeDarknetRows(const cv::Mat& rows, cv::Size net, float min_score,
                                         const std::vector<bool>& allowed) {
  CV_Assert(rows.type() == CV_32F && rows.dims == 2 && rows.cols > 5);
  std::vector<Detection> out;
  const int num_classes = rows.cols - 5;
  for (int r = 0; r < rows.rows; ++r) {
    const float* row = rows.ptr<float>(r);
    const auto [cls, score] = BestClass(row + 5, num_classes, allowed);
    if (score < min_score) continue;
    out.push_back(FromCenter(row[0] * net.width, row[1] * net.height, row[2] * net.width,
                             row[3] * net.height, cls, score));
  }
  return out;
}

std::vector<Detection> DecodeYolox(const cv::Mat& out_tensor, cv::Size net, float min_score,
                                   const std::vector<bool>& allowed) {
  CV_Assert(out_tensor.type() == CV_32F && out_tensor.isContinuous());
  const int cols = out_tensor.size[out_tensor.dims - 1];
  CV_Assert(cols > 5);
  const size_t anchors = Elements(out_tensor) / static_cast<size_t>(cols);
  const float* data = out_tensor.ptr<float>();
  std::vector<Detection> out;
  size_t index = 0;
  for (int stride : {8, 16, 32}) {
    const int grid_w = net.width / stride, grid_h = net.height / stride;
    for (int gy = 0; gy < grid_h; ++gy) {
      for (int gx = 0; gx < grid_w; ++gx, ++index) {
        CV_Assert(index < anchors);
        const float* row = data + index * cols;
        const auto [cls, cls_score] = BestClass(row + 5, cols - 5, allowed);
        const float score = row[4] * cls_score;
        if (score < min_score) continue;
        out.push_back(FromCenter((row[0] + gx) * stride, (row[1] + gy) * stride,
                                 std::exp(row[2]) * stride, std::exp(row[3]) * stride, cls, score));
      }
    }
  }
  CV_Assert(index == anchors);
  return out;
}

std::vector<Detection> DecodeFastestDet(const cv::Mat& out_tensor, cv::Size net, float min_score,
                                        const std::vector<bool>& allowed) {
  CV_Assert(out_tensor.type() == CV_32F && out_tensor.dims == 4 && out_tensor.isContinuous());
  const int channels = out_tensor.size[1], grid_h = out_tensor.size[2], grid_w = out_tensor.size[3];
  CV_Assert(channels > 5);
  const float* data = out_tensor.ptr<float>();
  const size_t plane = static_cast<size_t>(grid_h) * grid_w;
  std::vector<Detection> out;
  std::vector<float> cls_scores(channels - 5);
  for (int gy = 0; gy < grid_h; ++gy) {
    for (int gx = 0; gx < grid_w; ++gx) {
      const size_t cell = static_cast<size_t>(gy) * grid_w + gx;
      auto at = [&](int c) { return data[c * plane + cell]; };
      for (int c = 5; c < channels; ++c) cls_scores[c - 5] = at(c);
      const auto [cls, cls_score] = BestClass(cls_scores.data(), channels - 5, allowed);
      const float score = std::pow(std::max(at(0), 0.f), 0.6f) * std::pow(std::max(cls_score, 0.f), 0.4f);
      if (score < min_score) continue;
      const float cx = (gx + std::tanh(at(1))) / grid_w, cy = (gy + std::tanh(at(2))) / grid_h;
      const float w = Sigmoid(at(3)), h = Sigmoid(at(4));
      out.push_back(FromCenter(cx * net.width, cy * net.height, w * net.width, h * net.height, cls, score));
    }
  }
  return out;
}

std::vector<Detection> DecodeNanoDetLevel(const cv::Mat& cls, const cv::Mat& reg, int stride,
                                          cv::Size net, float min_score,
                                          const std::vector<bool>& allowed) {
  CV_Assert(cls.type() == CV_32F && reg.type() == CV_32F && cls.isContinuous() && reg.isContinuous());
  const int num_classes = cls.size[cls.dims - 1];
  const int reg_cols = reg.size[reg.dims - 1];
  CV_Assert(reg_cols % 4 == 0 && reg_cols >= 8);
  const int bins = reg_cols / 4;
  const int grid_w = (net.width + stride - 1) / stride, grid_h = (net.height + stride - 1) / stride;
  const size_t cells = Elements(cls) / static_cast<size_t>(num_classes);
  CV_Assert(cells == static_cast<size_t>(grid_w) * grid_h && Elements(reg) / reg_cols == cells);
  const float* cls_data = cls.ptr<float>();
  const float* reg_data = reg.ptr<float>();
  std::vector<Detection> out;
  std::vector<float> prob(bins);
  for (size_t cell = 0; cell < cells; ++cell) {
    const auto [label, score] = BestClass(cls_data + cell * num_classes, num_classes, allowed);
    if (score < min_score) continue;
    float dist[4];
    for (int side = 0; side < 4; ++side) {
      const float* logits = reg_data + cell * reg_cols + side * bins;
      const float top = *std::max_element(logits, logits + bins);
      float sum = 0.f, integral = 0.f;
      for (int b = 0; b < bins; ++b) {
        prob[b] = std::exp(logits[b] - top);
        sum += prob[b];
      }
      for (int b = 0; b < bins; ++b) integral += prob[b] * b;
      dist[side] = integral / sum * stride;
    }
    const float cx = (static_cast<float>(cell % grid_w) + 0.5f) * stride;
    const float cy = (static_cast<float>(cell / grid_w) + 0.5f) * stride;
    Detection d;
    d.box = cv::Rect2f(cx - dist[0], cy - dist[1], dist[0] + dist[2], dist[1] + dist[3]);
    d.class_id = label;
    d.score = score;
    out.push_back(d);
  }
  return out;
}

float BoxIou(const cv::Rect2f& a, const cv::Rect2f& b) {
  const float inter = (a & b).area();
  const float uni = a.area() + b.area() - inter;
  return uni > 0.f ? inter / uni : 0.f;
}

std::vector<Detection> NonMaxSuppression(std::vector<Detection> detections, float max_iou) {
  std::stable_sort(detections.begin(), detections.end(),
                   [](const Detection& a, const Detection& b) { return a.score > b.score; });
  std::vector<Detection> kept;
  for (const Detection& d : detections) {
    bool suppressed = false;
    for (const Detection& k : kept) {
      if (k.class_id == d.class_id && BoxIou(k.box, d.box) > max_iou) {
        suppressed = true;
        break;
      }
    }
    if (!suppressed) kept.push_back(d);
  }
  return kept;
}

}  // namespace dynorb
