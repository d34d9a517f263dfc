#include "dynorb/synth/scene.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace dynorb::synth {

double SceneBuilder::LightAt(const Eigen::Vector3d& point, const Eigen::Vector3d& normal) const {
  double light = 0.42;  // ambient (bright office with white walls)
  for (const Light& l : lights_) {
    const Eigen::Vector3d to_light = l.position - point;
    const double dist = to_light.norm();
    const double cos_n = normal.dot(to_light) / dist;
    if (cos_n <= 0.0) continue;
    double visibility = 1.0;
    for (const Occluder& o : occluders_) {
      if (!((point.z() < o.z - 1e-3 && l.position.z() > o.z) ||
            (point.z() > o.z + 1e-3 && l.position.z() < o.z)))
        continue;
      const double s = (o.z - point.z()) / to_light.z();
      const Eigen::Vector3d hit = point + s * to_light;
      if (hit.x() > o.x0 && hit.x() < o.x1 && hit.y() > o.y0 && hit.y() < o.y1) visibility *= 0.35;
    }
    light += l.power * visibility * (0.35 + 0.65 * cos_n) / (1.0 + 0.25 * dist * dist);
  }
  return std::clamp(light, 0.3, 1.3);
}

cv::Mat SceneBuilder::Lit(const cv::Mat& bgr, const Eigen::Vector3d& origin,
                          const Eigen::Vector3d& u, const Eigen::Vector3d& v) const {
  const Eigen::Vector3d normal = v.cross(u).normalized();  // front side: u right, v down
  const int gx = std::clamp(static_cast<int>(u.norm() * 5) + 2, 2, 40);
  const int gy = std::clamp(static_cast<int>(v.norm() * 5) + 2, 2, 40);
  cv::Mat grid(gy, gx, CV_32F);
  for (int j = 0; j < gy; ++j)
    for (int i = 0; i < gx; ++i)
      grid.at<float>(j, i) = static_cast<float>(
          LightAt(origin + u * (i / (gx - 1.0)) + v * (j / (gy - 1.0)) + normal * 0.01, normal));
  cv::Mat light;
  cv::resize(grid, light, bgr.size(), 0, 0, cv::INTER_LINEAR);
  cv::Mat light3;
  cv::merge(std::vector<cv::Mat>{light, light, light}, light3);
  cv::Mat out;
  cv::multiply(bgr, light3, out, 1.0, CV_8UC3);
  return out;
}

void SceneBuilder::AddRect(const Eigen::Vector3d& origin, const Eigen::Vector3d& u,
                           const Eigen::Vector3d& v, const TextureMaker& make, double px_per_m,
                           double cell_m, int object_id) {
  const cv::Size size(std::clamp(static_cast<int>(u.norm() * px_per_m), 4, 2048),
                      std::clamp(static_cast<int>(v.norm() * px_per_m), 4, 2048));
  const Texture* texture = scene_->Add(MakeTexture(Lit(make(size), origin, u, v)));
  const int nu = std::max(1, static_cast<int>(std::ceil(u.norm() / cell_m)));
  const int nv = std::max(1, static_cast<int>(std::ceil(v.norm() / cell_m)));
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      DrawQuad q;
      q.origin = origin + u * (static_cast<double>(i) / nu) + v * (static_cast<double>(j) / nv);
      q.axis_u = u / nu;
      q.axis_v = v / nv;
      q.texture = texture;
      // Texel edges: the quad's a in [0,1] covers [-0.5, W-0.5] of the texture.
      const double tw = static_cast<double>(size.width) / nu,
                   th = static_cast<double>(size.height) / nv;
      q.tex_rect = cv::Rect2d(-0.5 + i * tw, -0.5 + j * th, tw, th);
      q.object_id = object_id;
      scene_->static_quads.push_back(q);
    }
  }
}

void SceneBuilder::AddPicture(const Eigen::Vector3d& origin, const Eigen::Vector3d& u,
                              const Eigen::Vector3d& v, const cv::Mat& bgr) {
  const double px_per_m = std::max(bgr.cols / u.norm(), bgr.rows / v.norm());
  AddRect(
      origin, u, v,
      [&bgr](cv::Size size) {
        cv::Mat resized;
        cv::resize(bgr, resized, size, 0, 0, cv::INTER_AREA);
        return resized;
      },
      std::min(px_per_m, 1200.0));
}

std::vector<DrawQuad> SceneBuilder::MakeBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                            const TextureMaker& sides, double px_per_m,
                                            const TextureMaker& top, int object_id) {
  const Eigen::Vector3d d = hi - lo;
  const Eigen::Vector3d ex(d.x(), 0, 0), ey(0, d.y(), 0), ez(0, 0, d.z());
  struct Face {
    Eigen::Vector3d origin, u, v;
    bool is_top;
  };
  // Each face as seen from outside: texture x along u (right), y along v (down).
  const Face faces[5] = {
      {lo + ez, ex, -ez, false},             // front (-y)
      {lo + ex + ey + ez, -ex, -ez, false},  // back (+y)
      {lo + ey + ez, -ey, -ez, false},       // left (-x)
      {lo + ex + ez, ey, -ez, false},        // right (+x)
      {lo + ey + ez, ex, -ey, true},         // top (+z)
  };
  std::vector<DrawQuad> quads;
  for (const Face& f : faces) {
    if (f.u.norm() < 1e-6 || f.v.norm() < 1e-6) continue;
    const TextureMaker& make = (f.is_top && top) ? top : sides;
    const cv::Size size(std::clamp(static_cast<int>(f.u.norm() * px_per_m), 4, 2048),
                        std::clamp(static_cast<int>(f.v.norm() * px_per_m), 4, 2048));
    DrawQuad q;
    q.origin = f.origin;
    q.axis_u = f.u;
    q.axis_v = f.v;
    q.texture = scene_->Add(MakeTexture(Lit(make(size), f.origin, f.u, f.v)));
    q.tex_rect = cv::Rect2d(-0.5, -0.5, size.width, size.height);
    q.object_id = object_id;
    quads.push_back(q);
  }
  return quads;
}

void SceneBuilder::AddBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                          const TextureMaker& sides, double px_per_m, const TextureMaker& top) {
  for (const DrawQuad& q : MakeBox(lo, hi, sides, px_per_m, top)) scene_->static_quads.push_back(q);
}

}  // namespace dynorb::synth
