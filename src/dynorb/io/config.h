// Typed camera/system configuration, loaded from YAML through ConfigSchema (config_schema.h).
//
// Accepted keys (all optional; absent keys keep the defaults below):
//   ORB-SLAM2 settings keys, so existing TUM1/2/3.yaml files load unchanged:
//     Camera.fx/fy/cx/cy/k1/k2/p1/p2/k3/width/height/fps/bf/RGB, ThDepth, DepthMapFactor,
//     ORBextractor.nFeatures/scaleFactor/nLevels/iniThFAST/minThFAST;  Viewer.* is ignored.
//   Our sections:
//     dataset: depth_factor, max_difference_s, offset_s, associations_file, load_ground_truth,
//              check_images_exist   (TumSequenceOptions)
// DepthMapFactor and dataset.depth_factor are the same quantity: setting one sets both; setting
// both to different values is an error. Unknown keys are an InputError naming key and file:line.
// Other modules add sections with BindSystemConfig() + ConfigSchema::Section() (see
// config_schema.h); nothing here needs to change.
#pragma once

#include <string>

#include "dynorb/core/keypoint_observation.h"
#include "dynorb/core/orb_limits.h"
#include "dynorb/core/pinhole_camera.h"
#include "dynorb/io/config_schema.h"
#include "dynorb/io/tum_sequence.h"

namespace dynorb {

struct CameraConfig {
  // Intrinsics, distortion (OpenCV order) and image size; must be set by the file (fx > 0).
  PinholeCamera camera;
  // Frame rate of the sequence (Camera.fps).
  double fps = 30.0;
  // Virtual stereo baseline times fx, in pixel*metres (Camera.bf); baseline_m = bf / fx.
  double bf = 40.0;
  // Close/far depth threshold in multiples of the baseline (ThDepth; ORB-SLAM2's TUM files: 40;
  // 50 measured better on Kinect-like depth, docs/slam_core.md).
  double th_depth = 50.0;
  // Depth noise as a disparity standard deviation in px (DepthDisparitySigma; 0 = ORB-SLAM2's
  // u_r residual with the keypoint's sigma). See RgbdSensor::disparity_sigma_px.
  double disparity_sigma_px = kDefaultDisparitySigmaPx;
  // Raw depth units per metre (DepthMapFactor); mirrors dataset.depth_factor.
  double depth_map_factor = 5000.0;
  // ORB-SLAM2's Camera.RGB flag (1 = treat images as RGB, 0 = BGR when converting to grey).
  // dynorb frames are always BGR as decoded by OpenCV (RgbdFrame::rgb); ORB-SLAM2 also loads BGR
  // but its TUM files say 1, so it converts with swapped R/B weights. Kept for compatibility:
  // honour it only to reproduce ORB-SLAM2's grey images exactly.
  bool rgb_order = true;

  double baseline_m() const { return bf / camera.fx; }
  // Points closer than this are "close" (ORB-SLAM2: ThDepth * bf / fx).
  double close_depth_threshold_m() const { return th_depth * baseline_m(); }
  // Throws InputError for non-positive focal lengths/sizes/fps/bf/th_depth/depth factor.
  void Validate() const;
};

struct OrbConfig {
  // Number of ORB features per image (ORBextractor.nFeatures).
  int n_features = 1000;
  // Scale factor between pyramid levels (ORBextractor.scaleFactor), in [1.05, 4].
  double scale_factor = 1.2;
  // Number of pyramid levels (ORBextractor.nLevels).
  int n_levels = 8;
  // Initial FAST threshold (ORBextractor.iniThFAST).
  int ini_th_fast = 20;
  // Fallback FAST threshold for cells without corners (ORBextractor.minThFAST), <= ini_th_fast.
  int min_th_fast = 7;
  void Validate() const;
};

struct SystemConfig {
  CameraConfig camera;
  OrbConfig orb;
  TumSequenceOptions dataset;
};

// Declares all keys of `config` in `schema` (ORB-SLAM2 root keys, Viewer.* ignored, the
// "dataset" section) and registers the cross-field check + Validate() calls as finalizers.
// `config` must outlive the schema's use.
void BindSystemConfig(SystemConfig* config, ConfigSchema* schema);

// Loads one YAML file into a SystemConfig (defaults for absent keys). Throws InputError.
SystemConfig LoadSystemConfig(const std::string& path);

// The YAML text / file (atomic write) of the effective configuration; loads back identically.
std::string SystemConfigToYaml(const SystemConfig& config);
void WriteSystemConfig(const std::string& path, const SystemConfig& config);

}  // namespace dynorb
