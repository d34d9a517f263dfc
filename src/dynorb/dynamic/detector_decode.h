// Pure pre/post-processing maths of the object detectors (no cv::dnn here, so every step is
// unit-tested on constructed tensors): the image -> network-input transform (plain resize or
// letterbox), the output decoders of each supported model family, and class-wise NMS.
// Each decoder gives a cell the best-scoring class among `allowed` (every class when it is empty,
// else one flag per class of the output).
//
// Coordinates: decoders return boxes in network-input pixels; ResizeTransform maps them back to
// image pixels (x_image = (x_net - pad_x) / scale_x).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace dynorb {

struct Detection {
  cv::Rect2f box;     // Image pixels (or network pixels before MapToImage), top-left + size.
  int class_id = -1;  // Index into the model's class names.
  float score = 0.f;  // Confidence in [0, 1].
};

// network = image * scale + pad (per axis).
struct ResizeTransform {
  double scale_x = 1.0, scale_y = 1.0;
  double pad_x = 0.0, pad_y = 0.0;
  cv::Size net_size;
  cv::Size resized_size;  // Size of the resized image inside the network input.
};

// Plain resize to net_size (aspect ratio not kept): darknet YOLO, FastestDet.
ResizeTransform StretchTransform(cv::Size image, cv::Size net);
// Aspect-preserving resize; the image is placed top-left (YOLOX) or centred (NanoDet).
ResizeTransform LetterboxTransform(cv::Size image, cv::Size net, bool centered);
// Builds the CV_8UC3 network-input image (resized, padded with `pad_value`).
cv::Mat ApplyResize(const cv::Mat& bgr, const ResizeTransform& t, const cv::Scalar& pad_value);
// Maps boxes from network to image pixels and clips them to the image; drops empty boxes.
std::vector<Detection> MapToImage(const std::vector<Detection>& net_boxes, const ResizeTransform& t,
                                  cv::Size image);

// OpenCV's darknet [yolo] output: rows of (cx, cy, w, h normalised to the network input, obj,
// C class scores already multiplied by obj). One row per anchor cell, N x (5 + C), CV_32F.
std::vector<Detection> DecodeDarknetRows(const cv::Mat& rows, cv::Size net, float min_score,
                                         const std::vector<bool>& allowed = {});

// YOLOX: 1 x A x (5 + C) raw grid outputs over strides {8, 16, 32} (row-major grid cells per
// stride): cx = (tx + gx) * s, w = exp(tw) * s; obj and cls already sigmoid; score = obj * cls.
std::vector<Detection> DecodeYolox(const cv::Mat& out, cv::Size net, float min_score,
                                   const std::vector<bool>& allowed = {});

// FastestDet: 1 x (5 + C) x H x W: [obj, tx, ty, tw, th, cls...]; obj sigmoid, cls softmax
// already applied; score = obj^0.6 * cls^0.4; cx = (gx + tanh(tx)) / W, w = sigmoid(tw), both
// normalised to the network input.
std::vector<Detection> DecodeFastestDet(const cv::Mat& out, cv::Size net, float min_score,
                                        const std::vector<bool>& allowed = {});

// NanoDet (GFL head), one stride level: cls N x C (sigmoid applied), reg N x 4(R+1) (left, top,
// right, bottom distance distributions over bins 0..R; distance = sum softmax * bin * stride),
// cells row-major over a ceil(net/stride) grid, centre ((gx + 0.5) s, (gy + 0.5) s).
std::vector<Detection> DecodeNanoDetLevel(const cv::Mat& cls, const cv::Mat& reg, int stride,
                                          cv::Size net, float min_score,
                                          const std::vector<bool>& allowed = {});

// Intersection over union of two boxes (0 for empty boxes).
float BoxIou(const cv::Rect2f& a, const cv::Rect2f& b);
// Greedy class-wise NMS: highest score first, drops boxes of the same class with IoU > max_iou.
// Ties broken by input order, so the result is deterministic. Sorted by decreasing score.
std::vector<Detection> NonMaxSuppression(std::vector<Detection> detections, float max_iou);

}  // namespace dynorb
