#include "dynorb/synth/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "dynorb/core/angles.h"
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

// A 256 x 256 sprite whose colour encodes its texel (blue = column, green = row) and whose
// bulge (fraction of the width) is given per texel; alpha 1 everywhere.
template <typename BulgeFn>
Texture CoordinateSprite(BulgeFn bulge) {
  cv::Mat bgr(256, 256, CV_8UC3);
  cv::Mat alpha_bulge(256, 256, CV_32FC2);
  for (int r = 0; r < 256; ++r)
    for (int c = 0; c < 256; ++c) {
      bgr.at<cv::Vec3b>(r, c) = cv::Vec3b(static_cast<uchar>(c), static_cast<uchar>(r), 0);
      alpha_bulge.at<cv::Vec2f>(r, c) = cv::Vec2f(1.f, static_cast<float>(bulge(c, r)));
    }
  return MakeSpriteFromMaps(bgr, alpha_bulge);
}

// Texel (column, row) that the sprite quad's surface at height h (along the unit normal towards
// the camera at the origin) shows on the ray through pixel (u, v); also its depth. Camera frame.
Eigen::Vector3d RayHitsRaisedSprite(const PinholeCamera& cam, double u, double v, const DrawQuad& q_cam, double h) {
  const Eigen::Vector3d n0 = q_cam.axis_u.cross(q_cam.axis_v).normalized();
  const Eigen::Vector3d n = n0.dot(q_cam.origin) > 0 ? -n0 : n0;
  const Eigen::Vector3d ray((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
  const double z = (n.dot(q_cam.origin) + h) / n.dot(ray);
  const Eigen::Vector3d on_plane = z * ray - h * n - q_cam.origin;
  const double a = on_plane.dot(q_cam.axis_u) / q_cam.axis_u.squaredNorm();
  const double b = on_plane.dot(q_cam.axis_v) / q_cam.axis_v.squaredNorm();
  return {q_cam.tex_rect.x + a * q_cam.tex_rect.width, q_cam.tex_rect.y + b * q_cam.tex_rect.height, z};
}

TEST(Renderer, ObliqueSpriteShowsTheTexelWhereTheRayMeetsItsRaisedSurface) {
  // A sprite raised uniformly by 0.25 x 0.6 m = 15 cm, seen 35 degrees off its normal: the
  // billboard plane's own texel along a ray is up to ~45 texels away from the raised surface's.
  const PinholeCamera cam = TumFreiburg3Camera();
  const Texture sprite = CoordinateSprite([](int, int) { return 0.25; });
  const double angle = DegToRad(35.0);
  const Eigen::Vector3d across(std::cos(angle), 0, std::sin(angle));  // the sprite's u axis
  DrawQuad q = Rect(Eigen::Vector3d(-0.3 * std::cos(angle), -0.3, 1.3 - 0.3 * std::sin(angle)), 0.6 * across,
                    {0, 0.6, 0}, &sprite, 3);
  for (int supersample : {1, 2}) {
    Renderer renderer(cam, supersample);
    RenderedFrame frame;
    renderer.Render({q}, Rigid3d(), &frame);
    int checked = 0, colour_errors = 0;
    double max_depth_error = 0, max_plane_offset = 0;
    for (int v = 0; v < cam.height; v += 5)
      for (int u = 0; u < cam.width; u += 5) {
        // Pixels whose ray crosses the billboard itself (the quad is rasterised over its outline).
        const Eigen::Vector3d hit = RayHitsRaisedSprite(cam, u, v, q, 0.15);
        const Eigen::Vector3d plane_hit = RayHitsRaisedSprite(cam, u, v, q, 0.0);
        auto inside = [](const Eigen::Vector3d& t) { return t.x() > 2 && t.x() < 253 && t.y() > 2 && t.y() < 253; };
        if (!inside(hit) || !inside(plane_hit)) continue;
        ASSERT_EQ(frame.object_id.at<uchar>(v, u), 3) << u << "," << v;
        // Supersampling averages the texels of the pixel's sub-samples (an affine map here).
        const cv::Vec3b c = frame.rgb.at<cv::Vec3b>(v, u);
        colour_errors += std::abs(c[0] - hit.x()) > 1.0 || std::abs(c[1] - hit.y()) > 1.0;
        max_depth_error = std::max(max_depth_error, std::abs(frame.depth_m.at<float>(v, u) - hit.z()));
        max_plane_offset = std::max(max_plane_offset, std::abs(plane_hit.x() - hit.x()));
        ++checked;
      }
    EXPECT_GT(checked, 500);
    EXPECT_EQ(colour_errors, 0) << "supersample " << supersample;
    EXPECT_LT(max_depth_error, 1e-4);
    EXPECT_GT(max_plane_offset, 30.0);  // the plane's texel would be far off
  }
}

TEST(Renderer, SpriteStepShowsTheNearestSurfaceAlongEachRay) {
  // The lower half of the sprite is raised by 15 cm, the upper half by 3 cm, and the camera looks
  // at it from 35 degrees below its normal: along rays just above the step the raised lower half
  // stands in front of the upper half (which the billboard plane's texel, and a fixed-point
  // search started there, would show), and rays that clear it go on to the upper half.
  const PinholeCamera cam = TumFreiburg3Camera();
  const Texture sprite = CoordinateSprite([](int, int r) { return r >= 128 ? 0.25 : 0.05; });
  const double angle = DegToRad(35.0);
  const Eigen::Vector3d down(0, std::cos(angle), -std::sin(angle));  // the sprite's v axis
  const DrawQuad q = Rect(Eigen::Vector3d(-0.3, -0.3 * std::cos(angle), 1.3 + 0.3 * std::sin(angle)), {0.6, 0, 0},
                          0.6 * down, &sprite, 3);
  Renderer renderer(cam, 1);
  RenderedFrame frame;
  renderer.Render({q}, Rigid3d(), &frame);
  int raised = 0, behind = 0, hiding = 0, colour_errors = 0, depth_errors = 0;
  for (int v = 0; v < cam.height; v += 2)
    for (int u = 0; u < cam.width; u += 2) {
      const Eigen::Vector3d plane_hit = RayHitsRaisedSprite(cam, u, v, q, 0.0);
      if (plane_hit.x() < 2 || plane_hit.x() > 253 || plane_hit.y() < 2 || plane_hit.y() > 253) continue;
      const Eigen::Vector3d high = RayHitsRaisedSprite(cam, u, v, q, 0.15);
      const Eigen::Vector3d low = RayHitsRaisedSprite(cam, u, v, q, 0.03);
      Eigen::Vector3d expected;
      if (high.y() > 130 && high.y() < 253) {
        expected = high;
        ++raised;
        hiding += low.y() < 126 && plane_hit.y() < 126;  // the upper half lies behind it on this ray
      } else if (high.y() < 126 && low.y() < 126 && low.y() > 2) {
        expected = low;
        ++behind;
      } else {
        continue;  // the step between the halves, or off the texture
      }
      ASSERT_EQ(frame.object_id.at<uchar>(v, u), 3) << u << "," << v;
      const cv::Vec3b c = frame.rgb.at<cv::Vec3b>(v, u);
      colour_errors += std::abs(c[0] - expected.x()) > 1.0 || std::abs(c[1] - expected.y()) > 1.0;
      depth_errors += std::abs(frame.depth_m.at<float>(v, u) - expected.z()) > 1e-3;
    }
  EXPECT_GT(raised, 300);
  EXPECT_GT(behind, 300);
  EXPECT_GT(hiding, 100);
  EXPECT_EQ(colour_errors, 0);
  EXPECT_EQ(depth_errors, 0);
}

TEST(Renderer, SpriteColourAndDepthDescribeTheSamePointFromTwoViews) {
  // A dome-shaped body (up to 12 cm) seen from two camera positions 25 cm apart: the 3D point a
  // pixel's depth gives in the first view, seen in the second, shows the same texel there.
  const PinholeCamera cam = TumFreiburg3Camera();
  const Texture sprite = CoordinateSprite([](int c, int r) {
    const double x = (c - 127.5) / 128.0, y = (r - 127.5) / 128.0;
    return 0.2 * std::max(0.0, 1.0 - x * x - y * y);
  });
  const DrawQuad q = Rect({-0.3, -0.3, 1.4}, {0.6, 0, 0}, {0, 0.6, 0}, &sprite, 3);
  const Rigid3d cam1_from_world;
  const Rigid3d cam2_from_world(Eigen::Quaterniond(Eigen::AngleAxisd(-0.15, Eigen::Vector3d::UnitY())),
                                Eigen::Vector3d(-0.25, 0.05, 0.0));
  Renderer renderer(cam, 1);
  RenderedFrame view1, view2;
  renderer.Render({q}, cam1_from_world, &view1);
  renderer.Render({q}, cam2_from_world, &view2);
  int compared = 0, mismatches = 0;
  for (int v = 0; v < cam.height; v += 3)
    for (int u = 0; u < cam.width; u += 3) {
      const float z = view1.depth_m.at<float>(v, u);
      if (view1.object_id.at<uchar>(v, u) != 3 || z <= 0.f) continue;
      const Eigen::Vector3d point = cam.Unproject(Eigen::Vector2d(u, v), z);  // world = camera 1
      const Eigen::Vector2d px = cam.Project(cam2_from_world * point);
      const int u2 = static_cast<int>(std::lround(px.x())), v2 = static_cast<int>(std::lround(px.y()));
      if (u2 < 0 || v2 < 0 || u2 >= cam.width || v2 >= cam.height || view2.object_id.at<uchar>(v2, u2) != 3) continue;
      // Not hidden behind another part of the body in view 2.
      if (std::abs(view2.depth_m.at<float>(v2, u2) - (cam2_from_world * point).z()) > 0.01) continue;
      const cv::Vec3b c1 = view1.rgb.at<cv::Vec3b>(v, u), c2 = view2.rgb.at<cv::Vec3b>(v2, u2);
      // Rounding the projection to a pixel moves up to ~0.7 px, about one texel here.
      mismatches += std::abs(c1[0] - c2[0]) > 2 || std::abs(c1[1] - c2[1]) > 2;
      ++compared;
    }
  EXPECT_GT(compared, 1000);
  EXPECT_LE(mismatches, compared / 100);
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
