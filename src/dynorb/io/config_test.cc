#include "dynorb/io/config.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "dynorb/core/error.h"
#include "dynorb/core/test_expect_error.h"
#include "dynorb/io/test_temp_dir.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;

using testing::ExpectInputError;

void ExpectSameCamera(const PinholeCamera& a, const PinholeCamera& b) {
  EXPECT_EQ(a.fx, b.fx);
  EXPECT_EQ(a.fy, b.fy);
  EXPECT_EQ(a.cx, b.cx);
  EXPECT_EQ(a.cy, b.cy);
  EXPECT_EQ(a.k1, b.k1);
  EXPECT_EQ(a.k2, b.k2);
  EXPECT_EQ(a.p1, b.p1);
  EXPECT_EQ(a.p2, b.p2);
  EXPECT_EQ(a.k3, b.k3);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
}

class ConfigTest : public testing::TempDirTest {
 protected:
  ConfigTest() : TempDirTest("dynorb_config_") {}
};

// A settings file in the style of ORB-SLAM2's Examples/RGB-D/TUM1.yaml (OpenCV FileStorage):
// "%YAML:1.0" directive, comments, Viewer keys, and "Viewer.PointSize:2" without a space.
const char kOrbSlam2Style[] = R"(%YAML:1.0

#------------------------------------------
# Camera Parameters
#------------------------------------------
Camera.fx: 517.306408
Camera.fy: 516.469215
Camera.cx: 318.643040
Camera.cy: 255.313989

Camera.k1: 0.262383
Camera.k2: -0.953104
Camera.p1: -0.005358
Camera.p2: 0.002628
Camera.k3: 1.163314

Camera.width: 640
Camera.height: 480
Camera.fps: 30.0
Camera.bf: 40.0
Camera.RGB: 1
ThDepth: 40.0
DepthMapFactor: 5000.0

ORBextractor.nFeatures: 1000
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 20
ORBextractor.minThFAST: 7

#------------------------------------------
# Viewer Parameters
#------------------------------------------
Viewer.KeyFrameSize: 0.05
Viewer.KeyFrameLineWidth: 1
Viewer.GraphLineWidth: 0.9
Viewer.PointSize:2
Viewer.CameraSize: 0.08
Viewer.CameraLineWidth: 3
Viewer.ViewpointX: 0
Viewer.ViewpointY: -0.7
Viewer.ViewpointZ: -1.8
Viewer.ViewpointF: 500
)";

TEST_F(ConfigTest, ShippedTumConfigsLoadWithExactNumbers) {
  const std::pair<const char*, PinholeCamera> configs[] = {{"tum_fr1.yaml", TumFreiburg1Camera()},
                                                           {"tum_fr2.yaml", TumFreiburg2Camera()},
                                                           {"tum_fr3.yaml", TumFreiburg3Camera()}};
  for (const auto& [name, expected] : configs) {
    SCOPED_TRACE(name);
    const SystemConfig c = LoadSystemConfig(std::string(DYNORB_SOURCE_DIR "/config/") + name);
    ExpectSameCamera(c.camera.camera, expected);
    EXPECT_EQ(c.camera.fps, 30.0);
    EXPECT_EQ(c.camera.bf, 40.0);
    EXPECT_EQ(c.camera.th_depth, 50.0);
    EXPECT_EQ(c.camera.depth_map_factor, 5000.0);
    EXPECT_EQ(c.camera.disparity_sigma_px, 0.15);
    EXPECT_TRUE(c.camera.rgb_order);
    EXPECT_EQ(c.orb.n_features, 1000);
    EXPECT_EQ(c.orb.scale_factor, 1.2);
    EXPECT_EQ(c.orb.n_levels, 8);
    EXPECT_EQ(c.orb.ini_th_fast, 20);
    EXPECT_EQ(c.orb.min_th_fast, 7);
    EXPECT_EQ(c.dataset.depth_factor, 5000.0);
    EXPECT_EQ(c.dataset.max_difference_s, 0.02);
    EXPECT_EQ(c.dataset.offset_s, 0.0);
  }
  EXPECT_NEAR(
      LoadSystemConfig(DYNORB_SOURCE_DIR "/config/tum_fr3.yaml").camera.close_depth_threshold_m(),
      50.0 * 40.0 / 535.4, 1e-12);
}

TEST_F(ConfigTest, OrbSlam2SettingsFileLoads) {
  const SystemConfig c = LoadSystemConfig(Write("TUM1.yaml", kOrbSlam2Style));
  ExpectSameCamera(c.camera.camera, TumFreiburg1Camera());
  EXPECT_EQ(c.orb.n_features, 1000);
  EXPECT_EQ(c.dataset.depth_factor, 5000.0);
  // Same without the directive (plain YAML) and with "Camera.RGB: 0".
  std::string plain = kOrbSlam2Style;
  plain.erase(0, plain.find('\n'));
  plain.replace(plain.find("Camera.RGB: 1"), 13, "Camera.RGB: 0");
  EXPECT_FALSE(LoadSystemConfig(Write("plain.yaml", plain)).camera.rgb_order);
}

TEST_F(ConfigTest, UnknownKeysNameKeyAndFile) {
  const std::string base =
      "Camera.fx: 500\nCamera.fy: 500\nCamera.width: 640\nCamera.height: 480\n";
  const std::string typo = Write("typo.yaml", base + "Camera.fz: 500\n");
  ExpectInputError([&] { LoadSystemConfig(typo); }, typo + ":5: unknown key 'Camera.fz'");
  const std::string in_section = Write("section.yaml", base + "dataset:\n  depth_factr: 1000\n");
  ExpectInputError([&] { LoadSystemConfig(in_section); },
                   in_section + ":6: unknown key 'dataset.depth_factr'");
  const std::string unknown_section = Write("unknown.yaml", base + "tracking:\n  min_inliers: 3\n");
  ExpectInputError([&] { LoadSystemConfig(unknown_section); }, "unknown key 'tracking'");
  // Only Viewer.* is ignored, not arbitrary prefixes.
  ExpectInputError([&] { LoadSystemConfig(Write("v.yaml", base + "Viewers.X: 1\n")); },
                   "unknown key 'Viewers.X'");
}

TEST_F(ConfigTest, InvalidInputs) {
  const std::string base =
      "Camera.fx: 500\nCamera.fy: 500\nCamera.width: 640\nCamera.height: 480\n";
  ExpectInputError([&] { LoadSystemConfig((dir_ / "missing.yaml").string()); },
                   "config file not found");
  const std::string broken = Write("broken.yaml", base + "Camera.cx: [1, 2\n");
  // yaml-cpp reports the unterminated list at the end of the input (line 6).
  ExpectInputError([&] { LoadSystemConfig(broken); }, broken + ":6: invalid YAML");
  ExpectInputError([&] { LoadSystemConfig(Write("indent.yaml", "a: 1\n  b: 2\n")); },
                   "indent.yaml:2: invalid YAML: illegal map value");
  ExpectInputError([&] { LoadSystemConfig(dir_.string()); }, "config file not found");
  ExpectInputError(
      [&] { LoadSystemConfig(Write("a.yaml", base + "ORBextractor.nFeatures: 1000.5\n")); },
      "a.yaml:5: 'ORBextractor.nFeatures' expects an integer, got '1000.5'");
  ExpectInputError(
      [&] { LoadSystemConfig(Write("a.yaml", base + "ORBextractor.scaleFactor: 1.0001\n")); },
      "ORBextractor.scaleFactor must be in [1.05, 4] (ORB-SLAM2: 1.2), got 1.000100");
  ExpectInputError(
      [&] { LoadSystemConfig(Write("a.yaml", base + "ORBextractor.nFeatures: 2147483647\n")); },
      "ORBextractor.nFeatures must be <= 1000000");
  ExpectInputError([&] { LoadSystemConfig(Write("b.yaml", base + "Camera.cx: abc\n")); },
                   "b.yaml:5: 'Camera.cx' expects a number, got 'abc'");
  ExpectInputError([&] { LoadSystemConfig(Write("c.yaml", base + "Camera.RGB: maybe\n")); },
                   "'Camera.RGB' expects true/false");
  ExpectInputError([&] { LoadSystemConfig(Write("d.yaml", base + "Camera.fx: 1\n")); },
                   "d.yaml:5: duplicate key 'Camera.fx'");
  ExpectInputError([&] { LoadSystemConfig(Write("e.yaml", base + "dataset: 3\n")); },
                   "section 'dataset' must be a mapping");
  ExpectInputError([&] { LoadSystemConfig(Write("f.yaml", "- a\n- b\n")); }, "expected a mapping");
  // Validation failures name the file.
  ExpectInputError(
      [&] { LoadSystemConfig(Write("g.yaml", base + "ORBextractor.minThFAST: 30\n")); },
      "g.yaml: ORBextractor.minThFAST (30) must not exceed ORBextractor.iniThFAST (20)");
  ExpectInputError([&] { LoadSystemConfig(Write("h.yaml", "Camera.fy: 500\n")); },
                   "Camera.fx must be > 0");
  ExpectInputError(
      [&] { LoadSystemConfig(Write("i.yaml", base + "dataset:\n  max_difference_s: 0\n")); },
      "max_difference_s must be > 0");
  ExpectInputError([&] { LoadSystemConfig(Write("j.yaml", base + "DepthDisparitySigma: -0.1\n")); },
                   "j.yaml: DepthDisparitySigma must be >= 0");
  ExpectInputError([&] { LoadSystemConfig(Write("m.yaml", base + "Camera.fps: 1e300\n")); },
                   "m.yaml: Camera.fps must be <= 1000");
  // 0 is ORB-SLAM2's form; a value is read as given.
  EXPECT_EQ(LoadSystemConfig(Write("k.yaml", base + "DepthDisparitySigma: 0\n"))
                .camera.disparity_sigma_px,
            0.0);
  EXPECT_EQ(LoadSystemConfig(Write("l.yaml", base + "DepthDisparitySigma: 0.3\n"))
                .camera.disparity_sigma_px,
            0.3);
}

TEST_F(ConfigTest, DepthFactorKeysAreOneQuantity) {
  const std::string base =
      "Camera.fx: 500\nCamera.fy: 500\nCamera.width: 640\nCamera.height: 480\n";
  SystemConfig c = LoadSystemConfig(Write("a.yaml", base + "DepthMapFactor: 1000\n"));
  EXPECT_EQ(c.dataset.depth_factor, 1000.0);
  c = LoadSystemConfig(Write("b.yaml", base + "dataset:\n  depth_factor: 1000\n"));
  EXPECT_EQ(c.camera.depth_map_factor, 1000.0);
  c = LoadSystemConfig(
      Write("c.yaml", base + "DepthMapFactor: 1000\ndataset:\n  depth_factor: 1000.0\n"));
  EXPECT_EQ(c.camera.depth_map_factor, 1000.0);
  ExpectInputError(
      [&] {
        LoadSystemConfig(
            Write("d.yaml", base + "DepthMapFactor: 5000\ndataset:\n  depth_factor: 1000\n"));
      },
      "disagree");
}

TEST_F(ConfigTest, CrLfLineEndings) {
  std::string text = kOrbSlam2Style;
  std::string crlf;
  for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  const SystemConfig c = LoadSystemConfig(Write("crlf.yaml", crlf));
  ExpectSameCamera(c.camera.camera, TumFreiburg1Camera());
}

TEST_F(ConfigTest, SplitFilesLoadTogether) {
  // A system file without camera keys cannot load alone (the camera must be valid), but camera
  // file + system file can: finalizers run once after all files; later files override.
  const std::string system =
      Write("system.yaml", "ORBextractor.nFeatures: 1500\ndataset:\n  offset_s: 0.01\n");
  ExpectInputError([&] { LoadSystemConfig(system); }, "Camera.fx must be > 0");
  SystemConfig c;
  ConfigSchema schema;
  BindSystemConfig(&c, &schema);
  schema.LoadFiles({DYNORB_SOURCE_DIR "/config/tum_fr3.yaml", system});
  EXPECT_EQ(c.camera.camera.fx, 535.4);
  EXPECT_EQ(c.orb.n_features, 1500);
  EXPECT_EQ(c.dataset.offset_s, 0.01);
  EXPECT_EQ(c.dataset.max_difference_s, 0.02);
}

TEST_F(ConfigTest, WriteThenReadRoundTrips) {
  SystemConfig c = LoadSystemConfig(DYNORB_SOURCE_DIR "/config/tum_fr1.yaml");
  c.camera.camera.fx = 1.0 / 3.0;  // needs 17 significant digits
  c.camera.fps = 15.0;
  c.camera.rgb_order = false;
  c.camera.depth_map_factor = c.dataset.depth_factor = 1000.0;
  c.orb.n_features = 2000;
  c.orb.scale_factor = 1.25;
  c.dataset.max_difference_s = 0.03;
  c.dataset.offset_s = -0.0125;
  c.dataset.associations_file = "my assoc \"v2\".txt";
  c.dataset.check_images_exist = true;
  const std::string path = (dir_ / "effective_config.yaml").string();
  WriteSystemConfig(path, c);
  const SystemConfig r = LoadSystemConfig(path);
  ExpectSameCamera(r.camera.camera, c.camera.camera);
  EXPECT_EQ(r.camera.fps, 15.0);
  EXPECT_FALSE(r.camera.rgb_order);
  EXPECT_EQ(r.camera.bf, c.camera.bf);
  EXPECT_EQ(r.camera.th_depth, c.camera.th_depth);
  EXPECT_EQ(r.camera.depth_map_factor, 1000.0);
  EXPECT_EQ(r.orb.n_features, 2000);
  EXPECT_EQ(r.orb.scale_factor, 1.25);
  EXPECT_EQ(r.orb.n_levels, 8);
  EXPECT_EQ(r.dataset.depth_factor, 1000.0);
  EXPECT_EQ(r.dataset.max_difference_s, 0.03);
  EXPECT_EQ(r.dataset.offset_s, -0.0125);
  EXPECT_EQ(r.dataset.associations_file, c.dataset.associations_file);
  EXPECT_TRUE(r.dataset.check_images_exist);
  // Writing the re-read config gives the same text.
  EXPECT_EQ(SystemConfigToYaml(r), SystemConfigToYaml(c));
  // A failed write leaves nothing behind.
  EXPECT_THROW(WriteSystemConfig((dir_ / "no_dir" / "x.yaml").string(), c), InputError);
}

}  // namespace
}  // namespace dynorb
