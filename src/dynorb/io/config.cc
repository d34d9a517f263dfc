#include "dynorb/io/config.h"

#include <cmath>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

void RequirePositive(double value, const char* key) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw InputError(std::string(key) + " must be > 0, got " + std::to_string(value));
  }
}

}  // namespace

void CameraConfig::Validate() const {
  RequirePositive(camera.fx, "Camera.fx");
  RequirePositive(camera.fy, "Camera.fy");
  if (!std::isfinite(camera.cx) || !std::isfinite(camera.cy))
    throw InputError("Camera.cx/cy must be finite");
  for (double k : {camera.k1, camera.k2, camera.p1, camera.p2, camera.k3}) {
    if (!std::isfinite(k)) throw InputError("Camera distortion coefficients must be finite");
  }
  RequirePositive(camera.width, "Camera.width");
  RequirePositive(camera.height, "Camera.height");
  RequirePositive(fps, "Camera.fps");
  // It becomes an int (the keyframe spacing in frames): beyond int's range that cast is undefined.
  if (fps > 1000.0) throw InputError("Camera.fps must be <= 1000, got " + std::to_string(fps));
  RequirePositive(bf, "Camera.bf");
  RequirePositive(th_depth, "ThDepth");
  RequirePositive(depth_map_factor, "DepthMapFactor");
  if (!std::isfinite(disparity_sigma_px) || disparity_sigma_px < 0.0) {
    throw InputError("DepthDisparitySigma must be >= 0 (0: ORB-SLAM2's u_r residual), got " +
                     std::to_string(disparity_sigma_px));
  }
}

void OrbConfig::Validate() const {
  RequirePositive(n_features, "ORBextractor.nFeatures");
  if (n_features > kMaxOrbFeatures) {
    throw InputError("ORBextractor.nFeatures must be <= " + std::to_string(kMaxOrbFeatures) +
                     ", got " + std::to_string(n_features));
  }
  // Closer to 1, pyramid levels of a 640 x 480 image come out the same size: every keypoint
  // found on several levels (session 55: 1.0001 lost 19 of 20 frames without a word).
  if (!std::isfinite(scale_factor) || scale_factor < kMinOrbScaleFactor || scale_factor > 4.0) {
    throw InputError("ORBextractor.scaleFactor must be in [1.05, 4] (ORB-SLAM2: 1.2), got " +
                     std::to_string(scale_factor));
  }
  RequirePositive(n_levels, "ORBextractor.nLevels");
  RequirePositive(ini_th_fast, "ORBextractor.iniThFAST");
  RequirePositive(min_th_fast, "ORBextractor.minThFAST");
  if (min_th_fast > ini_th_fast) {
    throw InputError("ORBextractor.minThFAST (" + std::to_string(min_th_fast) +
                     ") must not exceed ORBextractor.iniThFAST (" + std::to_string(ini_th_fast) +
                     ")");
  }
}

void BindSystemConfig(SystemConfig* config, ConfigSchema* schema) {
  PinholeCamera& cam = config->camera.camera;
  schema->Root()
      .Add("Camera.fx", &cam.fx, "focal length x [px]")
      .Add("Camera.fy", &cam.fy, "focal length y [px]")
      .Add("Camera.cx", &cam.cx, "principal point x [px]")
      .Add("Camera.cy", &cam.cy, "principal point y [px]")
      .Add("Camera.k1", &cam.k1, "radial distortion k1 (OpenCV)")
      .Add("Camera.k2", &cam.k2, "radial distortion k2")
      .Add("Camera.p1", &cam.p1, "tangential distortion p1")
      .Add("Camera.p2", &cam.p2, "tangential distortion p2")
      .Add("Camera.k3", &cam.k3, "radial distortion k3")
      .Add("Camera.width", &cam.width, "image width [px]")
      .Add("Camera.height", &cam.height, "image height [px]")
      .Add("Camera.fps", &config->camera.fps, "frames per second")
      .Add("Camera.bf", &config->camera.bf, "baseline times fx [px*m]")
      .Add("Camera.RGB", &config->camera.rgb_order, "colour order: 1 = RGB, 0 = BGR")
      .Add("ThDepth", &config->camera.th_depth, "close/far threshold in baselines")
      .Add("DepthMapFactor", &config->camera.depth_map_factor, "raw depth units per metre")
      .Add("DepthDisparitySigma", &config->camera.disparity_sigma_px,
           "depth noise as a disparity standard deviation [px] in the RGB-D residual (0: "
           "ORB-SLAM2's u_r)")
      .Add("ORBextractor.nFeatures", &config->orb.n_features, "ORB features per image")
      .Add("ORBextractor.scaleFactor", &config->orb.scale_factor, "pyramid scale factor")
      .Add("ORBextractor.nLevels", &config->orb.n_levels, "pyramid levels")
      .Add("ORBextractor.iniThFAST", &config->orb.ini_th_fast, "initial FAST threshold")
      .Add("ORBextractor.minThFAST", &config->orb.min_th_fast, "fallback FAST threshold");
  schema->IgnorePrefix("Viewer.");

  TumSequenceOptions& ds = config->dataset;
  schema->Section("dataset", "TUM/Bonn RGB-D sequence reading")
      .Add("depth_factor", &ds.depth_factor, "raw depth units per metre (= DepthMapFactor)")
      .Add("max_difference_s", &ds.max_difference_s, "rgb/depth association window [s]")
      .Add("offset_s", &ds.offset_s, "added to depth stamps before association [s]")
      .Add("associations_file", &ds.associations_file,
           "explicit associations file; empty = associate")
      .Add("load_ground_truth", &ds.load_ground_truth, "read groundtruth.txt when present")
      .Add("check_images_exist", &ds.check_images_exist, "stat every image when opening")
      .OnLoaded([config, schema] {
        const bool camera_set = schema->IsSet("DepthMapFactor");
        const bool dataset_set = schema->IsSet("dataset.depth_factor");
        if (camera_set && dataset_set &&
            config->camera.depth_map_factor != config->dataset.depth_factor) {
          throw InputError("DepthMapFactor (" + std::to_string(config->camera.depth_map_factor) +
                           ") and dataset.depth_factor (" +
                           std::to_string(config->dataset.depth_factor) +
                           ") disagree; set only one");
        }
        if (dataset_set && !camera_set) {
          config->camera.depth_map_factor = config->dataset.depth_factor;
        } else {
          config->dataset.depth_factor = config->camera.depth_map_factor;
        }
        config->camera.Validate();
        config->orb.Validate();
        config->dataset.Validate();
      });
}

SystemConfig LoadSystemConfig(const std::string& path) {
  SystemConfig config;
  ConfigSchema schema;
  BindSystemConfig(&config, &schema);
  schema.Load(path);
  return config;
}

std::string SystemConfigToYaml(const SystemConfig& config) {
  SystemConfig copy = config;
  ConfigSchema schema;
  BindSystemConfig(&copy, &schema);
  return schema.ToYaml();
}

void WriteSystemConfig(const std::string& path, const SystemConfig& config) {
  SystemConfig copy = config;
  ConfigSchema schema;
  BindSystemConfig(&copy, &schema);
  schema.Write(path);
}

}  // namespace dynorb
