#include "dynorb/synth/renderer.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace dynorb::synth {

Renderer::Renderer(const PinholeCamera& camera, int supersample)
    : camera_(camera), supersample_(supersample) {
  CV_Assert(supersample >= 1 && supersample <= 4 && camera.width > 0 && camera.height > 0);
}

void Renderer::Prepare(const std::vector<DrawQuad>& quads, const Rigid3d& cam_from_world, int scale,
                       std::vector<Prepared>* prepared) const {
  // Pixel centre u at output resolution is at scale * u + (scale - 1) / 2 at this scale.
  const double fx = camera_.fx * scale, fy = camera_.fy * scale;
  const double cx = camera_.cx * scale + 0.5 * (scale - 1),
               cy = camera_.cy * scale + 0.5 * (scale - 1);
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  const Eigen::Matrix3d rot = cam_from_world.rotation.toRotationMatrix();
  prepared->resize(quads.size());
  for (size_t i = 0; i < quads.size(); ++i) {
    const DrawQuad& q = quads[i];
    Prepared& p = (*prepared)[i];
    p.visible = false;
    p.polygon.clear();
    const Eigen::Vector3d o = cam_from_world * q.origin;
    const Eigen::Vector3d u = rot * q.axis_u, v = rot * q.axis_v;
    const Eigen::Vector3d corners[4] = {o, o + u, o + u + v, o + v};
    // Clip against z >= near (Sutherland-Hodgman, one plane).
    Eigen::Vector3d clipped[8];
    int n = 0;
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d& a = corners[c];
      const Eigen::Vector3d& b = corners[(c + 1) % 4];
      const bool a_in = a.z() >= kNearM, b_in = b.z() >= kNearM;
      if (a_in) clipped[n++] = a;
      if (a_in != b_in) clipped[n++] = a + (b - a) * ((kNearM - a.z()) / (b.z() - a.z()));
    }
    if (n < 3) continue;
    const Eigen::Vector3d normal = u.cross(v).normalized();
    const double d = normal.dot(o);
    if (std::abs(d) < 1e-9) continue;  // seen edge-on
    double min_x = 1e30, max_x = -1e30, min_y = 1e30, max_y = -1e30;
    p.near_z = 1e30;
    for (int c = 0; c < n; ++c) {
      p.near_z = std::min(p.near_z, clipped[c].z());
      const Eigen::Vector2d px(fx * clipped[c].x() / clipped[c].z() + cx,
                               fy * clipped[c].y() / clipped[c].z() + cy);
      p.polygon.push_back(px);
      min_x = std::min(min_x, px.x());
      max_x = std::max(max_x, px.x());
      min_y = std::min(min_y, px.y());
      max_y = std::max(max_y, px.y());
    }
    const int w = camera_.width * scale, h = camera_.height * scale;
    if (max_x < 0 || max_y < 0 || min_x > w - 1 || min_y > h - 1) continue;
    p.a = normal.x() / (fx * d);
    p.b = normal.y() / (fy * d);
    p.c = (normal.z() - normal.x() * cx / fx - normal.y() * cy / fy) / d;
    Eigen::Matrix3d img_from_ab;
    img_from_ab.col(0) = k * u;
    img_from_ab.col(1) = k * v;
    img_from_ab.col(2) = k * o;
    Eigen::Matrix3d tex_from_ab;
    tex_from_ab << q.tex_rect.width, 0, q.tex_rect.x, 0, q.tex_rect.height, q.tex_rect.y, 0, 0, 1;
    p.img_from_tex = img_from_ab * tex_from_ab.inverse();
    p.tex_from_img = tex_from_ab * img_from_ab.inverse();
    p.width_m = q.axis_u.norm();
    p.plane_distance_m = std::abs(d);
    const Eigen::Vector3d toward_camera = d > 0 ? -normal : normal;
    p.texel_shift = p.tex_from_img * (k * toward_camera);
    p.visible = true;
  }
}

void Renderer::Rasterise(const std::vector<DrawQuad>& quads, const std::vector<Prepared>& prepared,
                         cv::Mat* inv_depth, cv::Mat* quad_index, cv::Mat* sprite_texel) {
  const int scale = inv_depth->cols / camera_.width;
  const int w = camera_.width * scale, h = camera_.height * scale;
  inv_depth->setTo(0.0f);
  quad_index->setTo(-1);
  const int blocks = (w + kBlock - 1) / kBlock;
  block_far_.assign(static_cast<size_t>(h) * blocks, 0.0f);
  order_.clear();
  for (size_t qi = 0; qi < quads.size(); ++qi)
    if (prepared[qi].visible) order_.push_back(static_cast<int>(qi));
  std::stable_sort(order_.begin(), order_.end(),
                   [&prepared](int a, int b) { return prepared[a].near_z < prepared[b].near_z; });
  for (const int qi : order_) {
    const Prepared& p = prepared[qi];
    const Texture* sprite = quads[qi].texture->IsSprite() ? quads[qi].texture : nullptr;
    double min_y = 1e30, max_y = -1e30;
    for (const auto& v : p.polygon) {
      min_y = std::min(min_y, v.y());
      max_y = std::max(max_y, v.y());
    }
    const int y_begin = std::max(0, static_cast<int>(std::ceil(min_y)));
    const int y_end = std::min(h - 1, static_cast<int>(std::floor(max_y)));
    const size_t n = p.polygon.size();
    const Eigen::Matrix3d& t = p.tex_from_img;
    for (int y = y_begin; y <= y_end; ++y) {
      double xl = 1e30, xr = -1e30;
      for (size_t e = 0; e < n; ++e) {
        const Eigen::Vector2d& a = p.polygon[e];
        const Eigen::Vector2d& b = p.polygon[(e + 1) % n];
        if ((a.y() <= y && b.y() >= y) || (b.y() <= y && a.y() >= y)) {
          if (a.y() == b.y()) {
            xl = std::min({xl, a.x(), b.x()});
            xr = std::max({xr, a.x(), b.x()});
          } else {
            const double x = a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
            xl = std::min(xl, x);
            xr = std::max(xr, x);
          }
        }
      }
      if (xl > xr) continue;
      const int x_begin = std::max(0, static_cast<int>(std::ceil(xl)));
      const int x_end = std::min(w, static_cast<int>(std::ceil(xr)));
      float* zrow = inv_depth->ptr<float>(y);
      int* irow = quad_index->ptr<int>(y);
      if (!sprite) {
        const float a = static_cast<float>(p.a);
        const float row_c = static_cast<float>(p.b * y + p.c);
        const int index = static_cast<int>(qi);
        float* block_far = &block_far_[static_cast<size_t>(y) * blocks];
        // Per block of kBlock pixels: skip it when the quad is behind everything drawn there
        // (quads come nearest first, so hidden walls cost little).
        for (int b = x_begin / kBlock; b * kBlock < x_end; ++b) {
          const int xs = std::max(x_begin, b * kBlock), xe = std::min(x_end, (b + 1) * kBlock);
          if (std::max(a * xs + row_c, a * (xe - 1) + row_c) <= block_far[b]) continue;
          for (int x = xs; x < xe; ++x) {
            const float iz = a * x + row_c;
            const bool nearer = iz > zrow[x];  // branch-free so that the loop vectorises
            zrow[x] = nearer ? iz : zrow[x];
            irow[x] = nearer ? index : irow[x];
          }
          const int bs = b * kBlock, be = std::min(w, bs + kBlock);
          float far = zrow[bs];
          for (int x = bs + 1; x < be; ++x) far = std::min(far, zrow[x]);
          block_far[b] = far;
        }
        continue;
      }
      // Sprites: the body is the billboard raised towards the camera by bulge(texel) * width.
      // Ray marching (as in parallax occlusion mapping): walk the ray from the highest possible
      // height H = max_bulge * width down to the plane in kSpriteSearchSteps steps; the first
      // sample at or under the surface brackets the nearest intersection, which bisection then
      // narrows to H / (kSpriteSearchSteps * 2^kSpriteBisections). Alpha, depth and the shading
      // texel all come from that point, so colour and depth describe the same surface point, and
      // a nearer part of the body hides a farther one.
      const cv::Mat& ab = sprite->alpha_bulge;
      const float max_tx = ab.cols - 0.5f, max_ty = ab.rows - 0.5f;
      const float clamp_x = std::max(0.0f, ab.cols - 1.001f),
                  clamp_y = std::max(0.0f, ab.rows - 1.001f);
      const size_t stride = ab.step1();
      const size_t next_x = ab.cols > 1 ? 2 : 0, next_y = ab.rows > 1 ? stride : 0;
      const float* ab_data = ab.ptr<float>(0);
      // Bilinear (alpha, bulge) at a texel; false outside the texture.
      auto lookup = [&](float tx, float ty, float* alpha, float* bulge) {
        if (!(tx >= -0.5f && ty >= -0.5f && tx <= max_tx && ty <= max_ty)) return false;
        const float cx = std::clamp(tx, 0.0f, clamp_x), cy = std::clamp(ty, 0.0f, clamp_y);
        const int ix = static_cast<int>(cx), iy = static_cast<int>(cy);
        const float fx = cx - ix, fy = cy - iy;
        const float* r0 = ab_data + iy * stride + 2 * ix;
        const float* r1 = r0 + next_y;
        const float a_top = r0[0] + fx * (r0[next_x] - r0[0]), a_bottom = r1[0] + fx * (r1[next_x] - r1[0]);
        const float b_top = r0[1] + fx * (r0[next_x + 1] - r0[1]),
                    b_bottom = r1[1] + fx * (r1[next_x + 1] - r1[1]);
        *alpha = a_top + fy * (a_bottom - a_top);
        *bulge = b_top + fy * (b_bottom - b_top);
        return true;
      };
      const float a = static_cast<float>(p.a), row_c = static_cast<float>(p.b * y + p.c);
      const float width_m = static_cast<float>(p.width_m);
      const float top = sprite->max_bulge * width_m;  // H
      const float inv_distance = static_cast<float>(1.0 / p.plane_distance_m);
      const float sx = static_cast<float>(p.texel_shift.x()), sy = static_cast<float>(p.texel_shift.y()),
                  sw = static_cast<float>(p.texel_shift.z());
      cv::Vec2f* trow = sprite_texel != nullptr ? sprite_texel->ptr<cv::Vec2f>(y) : nullptr;
      double nx = t(0, 0) * x_begin + t(0, 1) * y + t(0, 2);
      double ny = t(1, 0) * x_begin + t(1, 1) * y + t(1, 2);
      double nw = t(2, 0) * x_begin + t(2, 1) * y + t(2, 2);
      for (int x = x_begin; x < x_end; ++x, nx += t(0, 0), ny += t(1, 0), nw += t(2, 0)) {
        const float z_plane = 1.0f / (a * x + row_c);
        const float hx = static_cast<float>(nx), hy = static_cast<float>(ny), hw = static_cast<float>(nw);
        // The ray's point at height h: its texel, and whether it lies at or under the surface.
        float tx = 0.f, ty = 0.f;
        auto under_surface = [&](float height) {
          const float z = z_plane * (1.0f - height * inv_distance);
          const float tw = z * hw - height * sw;
          tx = (z * hx - height * sx) / tw;
          ty = (z * hy - height * sy) / tw;
          float alpha = 0.f, bulge = 0.f;
          return lookup(tx, ty, &alpha, &bulge) && alpha >= 0.5f && bulge * width_m >= height;
        };
        float above = -1.f, below = -1.f;  // heights bracketing the intersection (above: not under)
        float below_tx = 0.f, below_ty = 0.f;  // the texel at `below`
        for (int step = 0; step <= kSpriteSearchSteps; ++step) {
          const float height = top * (1.0f - static_cast<float>(step) / kSpriteSearchSteps);
          if (under_surface(height)) {
            below = height, below_tx = tx, below_ty = ty;
            break;
          }
          above = height;
        }
        if (below < 0.f) continue;  // the ray misses the body
        if (above >= 0.f) {
          for (int i = 0; i < kSpriteBisections; ++i) {
            const float mid = 0.5f * (above + below);
            if (under_surface(mid)) {
              below = mid, below_tx = tx, below_ty = ty;
            } else {
              above = mid;
            }
          }
        }
        const float z = z_plane * (1.0f - below * inv_distance);
        if (z <= kNearM) continue;
        const float iz = 1.0f / z;
        if (iz <= zrow[x]) continue;
        zrow[x] = iz;
        irow[x] = static_cast<int>(qi);
        if (trow != nullptr) trow[x] = cv::Vec2f(below_tx, below_ty);
      }
    }
  }
}

void Renderer::Shade(const std::vector<DrawQuad>& quads, const std::vector<Prepared>& prepared,
                     const cv::Mat& quad_index, const cv::Mat& sprite_texel, cv::Mat* colour) {
  const int nq = static_cast<int>(quads.size());
  std::vector<cv::Vec4i> box(
      nq, cv::Vec4i(std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), -1, -1));
  for (int y = 0; y < quad_index.rows; ++y) {
    const int* row = quad_index.ptr<int>(y);
    int x = 0;
    while (x < quad_index.cols) {
      const int q = row[x];
      int end = x + 1;
      while (end < quad_index.cols && row[end] == q) ++end;
      if (q >= 0) {
        cv::Vec4i& b = box[q];
        b[0] = std::min(b[0], x);
        b[1] = std::min(b[1], y);
        b[2] = std::max(b[2], end - 1);
        b[3] = std::max(b[3], y);
      }
      x = end;
    }
  }
  // Per quad: mip level from the texel footprint of a pixel at the centre of its visible box,
  // and the homography from pixels to texels of that level.
  struct Level {
    const cv::Mat* image = nullptr;
    double h[9];
    float inv_scale = 1.f;  // level-0 texel -> this level's texel
    bool sprite = false;    // texels come from sprite_texel (parallax-correct), not from h
  };
  std::vector<Level> levels(nq);
  for (int q = 0; q < nq; ++q) {
    const cv::Vec4i& b = box[q];
    if (b[2] < 0) continue;
    const Texture& texture = *quads[q].texture;
    const Eigen::Matrix3d& t = prepared[q].tex_from_img;
    const double x = 0.5 * (b[0] + b[2]), y = 0.5 * (b[1] + b[3]);
    const double tw = t(2, 0) * x + t(2, 1) * y + t(2, 2);
    const double tx = (t(0, 0) * x + t(0, 1) * y + t(0, 2)) / tw;
    const double ty = (t(1, 0) * x + t(1, 1) * y + t(1, 2)) / tw;
    const double j00 = (t(0, 0) - tx * t(2, 0)) / tw, j01 = (t(0, 1) - tx * t(2, 1)) / tw;
    const double j10 = (t(1, 0) - ty * t(2, 0)) / tw, j11 = (t(1, 1) - ty * t(2, 1)) / tw;
    const double texels_per_px = std::sqrt(std::abs(j00 * j11 - j01 * j10));
    int level =
        texels_per_px > 1.0 ? static_cast<int>(std::floor(std::log2(texels_per_px) + 0.25)) : 0;
    level = std::clamp(level, 0, static_cast<int>(texture.levels.size()) - 1);
    const double inv_scale = std::ldexp(1.0, -level);
    levels[q].image = &texture.levels[level];
    levels[q].inv_scale = static_cast<float>(inv_scale);
    levels[q].sprite = texture.IsSprite();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) levels[q].h[3 * r + c] = t(r, c) * (r < 2 ? inv_scale : 1.0);
  }
  // Perspective-correct bilinear texturing of each pixel from its quad's texture level, run by
  // run (a run is a horizontal stretch of pixels of one quad), in 8-bit fixed point.
  for (int y = 0; y < quad_index.rows; ++y) {
    const int* row = quad_index.ptr<int>(y);
    auto* out = colour->ptr<uchar>(y);
    int x = 0;
    while (x < quad_index.cols) {
      const int q = row[x];
      int end = x + 1;
      while (end < quad_index.cols && row[end] == q) ++end;
      if (q < 0) {
        std::fill(out + 3 * x, out + 3 * end, uchar{128});
        x = end;
        continue;
      }
      const Level& l = levels[q];
      const double* h = l.h;
      const cv::Mat& img = *l.image;
      const size_t step = img.step[0];
      const uchar* base = img.data;
      const float max_x = img.cols - 1.002f, max_y = img.rows - 1.002f;
      double nx = h[0] * x + h[1] * y + h[2], ny = h[3] * x + h[4] * y + h[5],
             nw = h[6] * x + h[7] * y + h[8];
      const cv::Vec2f* texel_row = l.sprite ? sprite_texel.ptr<cv::Vec2f>(y) : nullptr;
      for (; x < end; ++x) {
        float tx, ty;
        if (texel_row != nullptr) {
          tx = std::clamp(texel_row[x][0] * l.inv_scale, 0.0f, max_x);
          ty = std::clamp(texel_row[x][1] * l.inv_scale, 0.0f, max_y);
        } else {
          const float inv_w = 1.0f / static_cast<float>(nw);
          tx = std::clamp(static_cast<float>(nx) * inv_w, 0.0f, max_x);
          ty = std::clamp(static_cast<float>(ny) * inv_w, 0.0f, max_y);
          nx += h[0];
          ny += h[3];
          nw += h[6];
        }
        const int fx = static_cast<int>(tx * 256.0f), fy = static_cast<int>(ty * 256.0f);
        const int ix = fx >> 8, iy = fy >> 8, wx = fx & 255, wy = fy & 255;
        const uchar* p0 = base + iy * step + 3 * ix;
        const uchar* p1 = p0 + step;
        uchar* o = out + 3 * x;
        for (int c = 0; c < 3; ++c) {
          const int top = (p0[c] << 8) + wx * (p0[c + 3] - p0[c]);
          const int bottom = (p1[c] << 8) + wx * (p1[c + 3] - p1[c]);
          o[c] = static_cast<uchar>(((top << 8) + wy * (bottom - top) + 32768) >> 16);
        }
      }
    }
  }
}

void Renderer::Render(const std::vector<DrawQuad>& quads, const Rigid3d& cam_from_world,
                      RenderedFrame* out) {
  const int w = camera_.width, h = camera_.height, s = supersample_;
  for (const DrawQuad& q : quads) CV_Assert(q.texture != nullptr && !q.texture->levels.empty());
  inv_depth_full_.create(h, w, CV_32F);
  index_full_.create(h, w, CV_32S);
  if (s == 1) texel_full_.create(h, w, CV_32FC2);  // shading texels (only read at this scale)
  Prepare(quads, cam_from_world, 1, &prepared_full_);
  Rasterise(quads, prepared_full_, &inv_depth_full_, &index_full_, s == 1 ? &texel_full_ : nullptr);
  const std::vector<Prepared>* shade_prepared = &prepared_full_;
  const cv::Mat* shade_index = &index_full_;
  const cv::Mat* shade_texel = &texel_full_;
  if (s > 1) {
    inv_depth_super_.create(h * s, w * s, CV_32F);
    index_super_.create(h * s, w * s, CV_32S);
    texel_super_.create(h * s, w * s, CV_32FC2);
    Prepare(quads, cam_from_world, s, &prepared_super_);
    Rasterise(quads, prepared_super_, &inv_depth_super_, &index_super_, &texel_super_);
    shade_prepared = &prepared_super_;
    shade_index = &index_super_;
    shade_texel = &texel_super_;
  }
  colour_super_.create(h * s, w * s, CV_8UC3);
  Shade(quads, *shade_prepared, *shade_index, *shade_texel, &colour_super_);
  if (s > 1) {
    cv::resize(colour_super_, out->rgb, cv::Size(w, h), 0, 0, cv::INTER_AREA);
  } else {
    colour_super_.copyTo(out->rgb);
  }

  std::vector<uchar> object_of(quads.size() + 1, 0);  // shifted by one: index -1 -> 0
  for (size_t i = 0; i < quads.size(); ++i)
    object_of[i + 1] = static_cast<uchar>(quads[i].object_id);
  out->depth_m.create(h, w, CV_32F);
  out->object_id.create(h, w, CV_8U);
  for (int y = 0; y < h; ++y) {
    const float* iz = inv_depth_full_.ptr<float>(y);
    const int* idx = index_full_.ptr<int>(y);
    float* depth = out->depth_m.ptr<float>(y);
    uchar* id = out->object_id.ptr<uchar>(y);
    for (int x = 0; x < w; ++x) {
      depth[x] = iz[x] > 0.0f ? 1.0f / iz[x] : 0.0f;
      uchar obj = object_of[idx[x] + 1];
      if (obj == 0 && s > 1) {
        for (int dy = 0; dy < s && obj == 0; ++dy) {
          const int* srow = index_super_.ptr<int>(y * s + dy) + x * s;
          for (int dx = 0; dx < s; ++dx) obj = std::max(obj, object_of[srow[dx] + 1]);
        }
      }
      id[x] = obj;
    }
  }
}

}  // namespace dynorb::synth
