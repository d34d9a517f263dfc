#include "dynorb/synth/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/synth/figure.h"
#include "dynorb/synth/png_writer.h"
#include "dynorb/synth/procedural.h"

namespace dynorb::synth {
namespace {

Texture GreyNoise(cv::Scalar colour) {
  cv::RNG rng(3);
  return MakeTexture(NoisyColor(cv::Size(256, 256), colour, 0.2, 16.0, rng));
}

DrawQuad Rect(const Eigen::Vector3d& origin, const Eigen::Vector3d& u, const Eigen::Vector3d& v,
              const Texture* t, int id = 0) {
  DrawQuad q;
  q.origin = origin;
  q.axis_u = u;
  q.axis_v = v;
  q.texture = t;
  q.tex_rect = cv::Rect2d(-0.5, -0.5, t->width(), t->height());
  q.object_id = id;
  return q;
}

// Depth along the optical axis where the ray through pixel (u, v) meets the plane n.X = d.
double PlaneDepth(const PinholeCamera& cam, double u, double v, const Eigen::Vector3d& n,
                  double d) {
  const Eigen::Vector3d ray((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
  return d / n.dot(ray);
}

TEST(Renderer, ProjectedPointLandsOnItsPixelWithItsDepth) {
  const PinholeCamera cam = TumFreiburg3Camera();
  const Texture wall = GreyNoise({200, 200, 200}), dot = GreyNoise({20, 20, 20});
  // A tilted wall and a 4 cm square marker in front of it, seen by a rotated, moved camera.
  const Rigid3d world_from_cam(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.3, 1.0, 0.1).normalized())),
      Eigen::Vector3d(0.4, -0.2, 0.1));
  const Rigid3d cam_from_world = world_from_cam.Inverse();
  const Eigen::Vector3d wall_o = world_from_cam * Eigen::Vector3d(-4, -3, 3.0);
  const Eigen::Vector3d wall_u = world_from_cam.rotation * Eigen::Vector3d(8, 0, 2.0);
  const Eigen::Vector3d wall_v = world_from_cam.rotation * Eigen::Vector3d(0, 6, 0.5);
  const Eigen::Vector3d point_in_cam(0.31, -0.17, 2.0);
  const Eigen::Vector3d point = world_from_cam * point_in_cam;
  const Eigen::Vector3d du = world_from_cam.rotation * Eigen::Vector3d(0.04, 0, 0);
  const Eigen::Vector3d dv = world_from_cam.rotation * Eigen::Vector3d(0, 0.04, 0);
  std::vector<DrawQuad> quads = {Rect(wall_o, wall_u, wall_v, &wall),
                                 Rect(point - 0.5 * du - 0.5 * dv, du, dv, &dot, 7)};
  for (int supersample : {1, 2, 3}) {
    Renderer renderer(cam, supersample);
    RenderedFrame frame;
    renderer.Render(quads, cam_from_world, &frame);
    const Eigen::Vector2d px = cam.Project(point_in_cam);
    // The marker's pixel-centre coverage is centred on the projection.
    double su = 0, sv = 0, n = 0;
    for (int v = 0; v < cam.height; ++v)
      for (int u = 0; u < cam.width; ++u)
        if (frame.object_id.at<uchar>(v, u) == 7 &&
            std::abs(frame.depth_m.at<float>(v, u) - 2.0f) < 0.01f) {
          su += u;
          sv += v;
          n += 1;
        }
    ASSERT_GT(n, 50);
    EXPECT_NEAR(su / n, px.x(), 0.3) << "supersample " << supersample;
    EXPECT_NEAR(sv / n, px.y(), 0.3);
    // Exactly: a pixel is marked iff the ray through its centre hits the marker (supersample 1),
    // or at least then (larger supersampling also marks partly covered pixels).
    const Eigen::Vector3d m_o = cam_from_world * quads[1].origin;
    const Eigen::Vector3d m_u = cam_from_world.rotation * du, m_v = cam_from_world.rotation * dv;
    const Eigen::Vector3d m_n = m_u.cross(m_v);
    int mismatches = 0;
    for (int v = 0; v < cam.height; ++v)
      for (int u = 0; u < cam.width; ++u) {
        const Eigen::Vector3d ray((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
        const Eigen::Vector3d hit = ray * (m_n.dot(m_o) / m_n.dot(ray)) - m_o;
        const double a = hit.dot(m_u) / m_u.squaredNorm(), b = hit.dot(m_v) / m_v.squaredNorm();
        const bool inside = a > 1e-6 && a < 1 - 1e-6 && b > 1e-6 && b < 1 - 1e-6;
        const bool outside = a < -1e-6 || a > 1 + 1e-6 || b < -1e-6 || b > 1 + 1e-6;
        const bool marked = frame.object_id.at<uchar>(v, u) == 7;
        if ((inside && !marked) || (outside && marked && supersample == 1)) ++mismatches;
      }
    EXPECT_EQ(mismatches, 0);
    const int u0 = static_cast<int>(std::lround(px.x())),
              v0 = static_cast<int>(std::lround(px.y()));
    EXPECT_NEAR(frame.depth_m.at<float>(v0, u0), 2.0, 1e-5);
    EXPECT_LT(frame.rgb.at<cv::Vec3b>(v0, u0)[1], 60);
    // The wall's depth equals the analytic ray-plane intersection at every pixel centre.
    const Eigen::Vector3d o = cam_from_world * wall_o;
    const Eigen::Vector3d normal = (cam_from_world.rotation * wall_u.cross(wall_v)).normalized();
    double max_error = 0;
    for (int v = 0; v < cam.height; v += 7)
      for (int u = 0; u < cam.width; u += 7)
        if (frame.object_id.at<uchar>(v, u) == 0)
          max_error = std::max(max_error, std::abs(frame.depth_m.at<float>(v, u) -
                                                   PlaneDepth(cam, u, v, normal, normal.dot(o))));
    EXPECT_LT(max_error, 2e-5);
  }
}

TEST(Renderer, QuadsBehindTheCameraAreClippedAndOccludedFarQuadsHidden) {
  const PinholeCamera cam = TumFreiburg3Camera();
  const Texture a = GreyNoise({100, 100, 100});
  // A floor from behind the camera to 10 m ahead, and a wall at 5 m.
  std::vector<DrawQuad> quads = {Rect({-5, 1.0, -3}, {10, 0, 0}, {0, 0, 13}, &a),
                                 Rect({-5, -3, 5}, {10, 0, 0}, {0, 6, 0}, &a)};
  Renderer renderer(cam, 2);
  RenderedFrame frame;
  renderer.Render(quads, Rigid3d(), &frame);
  // Bottom row: floor at y = 1 m: depth = fy * 1 / (v - cy).
  const int v = cam.height - 1;
  EXPECT_NEAR(frame.depth_m.at<float>(v, 100), cam.fy * 1.0 / (v - cam.cy), 1e-4);
  // Above the horizon: the wall at 5 m.
  EXPECT_NEAR(frame.depth_m.at<float>(100, 300), 5.0, 1e-5);
  EXPECT_EQ(cv::countNonZero(frame.depth_m == 0), 0);
}

TEST(Renderer, SpriteHasABodyShapedDepthAndAlphaTestedMask) {
  const PinholeCamera cam = TumFreiburg3Camera();
  const Texture wall = GreyNoise({180, 180, 180});
  const Texture person = MakeSprite(MakeFigureSprites(5, 1, 400).front());
  const double height = 1.75, width = height * person.width() / person.height();
  std::vector<DrawQuad> quads = {
      Rect({-5, -4, 4}, {10, 0, 0}, {0, 8, 0}, &wall),
      Rect({-width / 2, -1.0, 2.0}, {width, 0, 0}, {0, height, 0}, &person, 1)};
  Renderer renderer(cam, 2);
  RenderedFrame frame;
  renderer.Render(quads, Rigid3d(), &frame);
  const cv::Mat mask = frame.object_id == 1;
  const int area = cv::countNonZero(mask);
  // The silhouette covers clearly less than the billboard rectangle.
  const double rect_area = (width * cam.fx / 2.0) * (height * cam.fy / 2.0);
  EXPECT_GT(area, 0.3 * rect_area);
  EXPECT_LT(area, 0.8 * rect_area);
  double min_depth = 10, max_depth = 0;
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u)
      if (mask.at<uchar>(v, u) && frame.depth_m.at<float>(v, u) < 3.0f) {  // centre on the person
        min_depth = std::min<double>(min_depth, frame.depth_m.at<float>(v, u));
        max_depth = std::max<double>(max_depth, frame.depth_m.at<float>(v, u));
      }
  EXPECT_LT(min_depth, 1.92);  // the torso bulges ~10 cm towards the camera
  EXPECT_GT(min_depth, 1.75);
  EXPECT_NEAR(max_depth, 2.0, 0.03);  // silhouette edges lie on the billboard
  // Between the legs the wall shows through.
  const int u_mid = static_cast<int>(std::lround(cam.cx));
  const int v_feet = static_cast<int>(std::lround(cam.fy * 0.7 / 2.0 + cam.cy));
  EXPECT_EQ(frame.object_id.at<uchar>(v_feet, u_mid), 0);
  EXPECT_NEAR(frame.depth_m.at<float>(v_feet, u_mid), 4.0, 1e-4);
}

TEST(PngWriter, RoundTripsThroughOpenCv) {
  cv::RNG rng(1);
  cv::Mat rgb(37, 53, CV_8UC3), grey(37, 53, CV_8UC1), depth(37, 53, CV_16UC1);
  rng.fill(rgb, cv::RNG::UNIFORM, 0, 256);
  rng.fill(grey, cv::RNG::UNIFORM, 0, 256);
  rng.fill(depth, cv::RNG::UNIFORM, 0, 65536);
  for (const cv::Mat& img : {rgb, grey, depth}) {
    const std::string png = EncodePng(img);
    const cv::Mat decoded =
        cv::imdecode(std::vector<uchar>(png.begin(), png.end()), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(decoded.type(), img.type());
    EXPECT_EQ(cv::norm(decoded, img, cv::NORM_INF), 0.0);
  }
}

}  // namespace
}  // namespace dynorb::synth
