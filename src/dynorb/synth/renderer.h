// Renderer: draws textured planar quads (and alpha-tested sprite billboards with a body-shaped
// depth bulge) into an RGB image, a depth map and a moving-object id map.
//
// A sprite's surface is its billboard plane pushed towards the camera by the texture's bulge
// (along the plane normal). Each pixel's ray is intersected with that surface (ray marching over
// planes parallel to the billboard, then bisection), and colour, alpha, depth and id all come
// from the texel of the nearest intersection, so a person's colour moves with their depth
// (parallax-correct). Only rays that cross the billboard's quad are traced.
//
// Geometry is exact: a quad is clipped against the near plane, rasterised by scanlines at pixel
// centres, and z-buffered with its analytic inverse depth (affine in pixel coordinates for a
// plane). Colour is rendered at `supersample` x the resolution with perspective-correct,
// mip-mapped texturing (cv::warpPerspective of the texture level whose texel size matches a
// pixel) and box-filtered down (cv::INTER_AREA): no aliasing corners. Depth and ids are rendered
// at the output resolution at exact pixel centres.
//
// Frames: quads are given in world coordinates, the pose as cam_from_world (camera: x right,
// y down, z forward; pixel centres at integer coordinates, see core/pinhole_camera.h).
// Owns scratch buffers: one Renderer per thread.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"
#include "dynorb/synth/texture.h"

namespace dynorb::synth {

// Quad corners: origin, origin + axis_u, origin + axis_u + axis_v, origin + axis_v. Quad point
// origin + a * axis_u + b * axis_v (a, b in [0, 1]) shows level-0 texel
// (tex_rect.x + a * tex_rect.width, tex_rect.y + b * tex_rect.height); a negative width mirrors.
struct DrawQuad {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis_u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d axis_v = Eigen::Vector3d::UnitY();
  const Texture* texture = nullptr;  // not owned; sprites are alpha-tested and bulge
  cv::Rect2d tex_rect;
  int object_id = 0;  // 0 = static scene, 1..255 = moving object
};

struct RenderedFrame {
  cv::Mat rgb;      // CV_8UC3 BGR
  cv::Mat depth_m;  // CV_32F: z (along the optical axis) at each pixel centre; 0 = no surface
  cv::Mat
      object_id;  // CV_8U: moving object seen in any part of the pixel (its centre first); 0 = none
};

class Renderer {
 public:
  Renderer(const PinholeCamera& camera, int supersample = 2);

  void Render(const std::vector<DrawQuad>& quads, const Rigid3d& cam_from_world,
              RenderedFrame* out);

  static constexpr double kNearM = 0.05;  // near clipping plane

 private:
  struct Prepared {
    bool visible = false;
    std::vector<Eigen::Vector2d> polygon;  // clipped, projected (pixels at this scale)
    double a = 0, b = 0, c = 0;            // inverse depth = a * x + b * y + c
    Eigen::Matrix3d img_from_tex;          // level-0 texels -> pixels at this scale
    Eigen::Matrix3d tex_from_img;
    double width_m = 0;  // |axis_u|, for the sprite bulge
    double near_z = 0;   // nearest clipped corner (drawing order)
    // Sprites: the surface at height h is the plane moved by h along its unit normal n towards
    // the camera. The camera's distance to the plane, and tex_from_img * K * n (homogeneous
    // texel shift per metre of height): the point that the ray through pixel x meets at height h,
    // moved back onto the plane by -h n, shows texel  z(h) * tex_from_img * x - h * texel_shift.
    double plane_distance_m = 0;
    Eigen::Vector3d texel_shift = Eigen::Vector3d::Zero();
  };
  static constexpr int kBlock = 16;       // pixels per block of the occlusion bound
  static constexpr int kSpriteSearchSteps = 8;  // ray-marching steps over a sprite's height range
  static constexpr int kSpriteBisections = 5;   // then bisection steps of the bracketed intersection

  void Prepare(const std::vector<DrawQuad>& quads, const Rigid3d& cam_from_world, int scale,
               std::vector<Prepared>* prepared) const;
  // Z-buffers all quads at this scale: inverse depth and winning quad index (-1 = none). Where a
  // sprite wins, `sprite_texel` (CV_32FC2; nullptr: not needed) holds the level-0 texel its
  // surface point shows.
  void Rasterise(const std::vector<DrawQuad>& quads, const std::vector<Prepared>& prepared,
                 cv::Mat* inv_depth, cv::Mat* quad_index, cv::Mat* sprite_texel);
  void Shade(const std::vector<DrawQuad>& quads, const std::vector<Prepared>& prepared,
             const cv::Mat& quad_index, const cv::Mat& sprite_texel, cv::Mat* colour);

  PinholeCamera camera_;
  int supersample_;
  std::vector<Prepared> prepared_full_, prepared_super_;
  std::vector<int> order_;        // visible quads, nearest first
  std::vector<float> block_far_;  // per row and block: smallest inverse depth drawn (0 = none)
  cv::Mat inv_depth_full_, index_full_, texel_full_, inv_depth_super_, index_super_, texel_super_, colour_super_;
};

}  // namespace dynorb::synth
