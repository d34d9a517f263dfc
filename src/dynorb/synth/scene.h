// Scene: the textures and static textured quads of a synthetic room, and SceneBuilder, which
// adds lit, tessellated rectangles and boxes to it.
//
// World frame: x right, y forward (into the room), z up; metres. Lighting (ceiling lights with
// soft shadows of horizontal occluders such as desk tops) is baked into each surface's own
// texture when it is added. Large surfaces are split into cells of at most `cell_m` so that each
// cell gets a well-matched mip level. The Scene owns its textures (stable addresses); it is
// immutable once built and may be shared by rendering threads.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "dynorb/synth/renderer.h"
#include "dynorb/synth/texture.h"

namespace dynorb::synth {

struct Scene {
  std::vector<std::unique_ptr<Texture>> textures;
  std::vector<DrawQuad> static_quads;

  const Texture* Add(Texture texture) {
    textures.push_back(std::make_unique<Texture>(std::move(texture)));
    return textures.back().get();
  }
};

// Makes the texture of one box face or rectangle given its size in texels.
using TextureMaker = std::function<cv::Mat(cv::Size)>;

class SceneBuilder {
 public:
  explicit SceneBuilder(Scene* scene) : scene_(scene) {}

  void AddLight(const Eigen::Vector3d& position, double power) {
    lights_.push_back({position, power});
  }
  // A horizontal rectangle [x0,x1]x[y0,y1] at height z that casts soft shadows downwards.
  void AddOccluder(double x0, double y0, double x1, double y1, double z) {
    occluders_.push_back({x0, y0, x1, y1, z});
  }

  // Light factor (1 = texture shown as is) at a point with the given unit normal.
  double LightAt(const Eigen::Vector3d& point, const Eigen::Vector3d& normal) const;

  // A lit rectangle with corners origin, +u, +u+v, +v as seen from its front side (u to the right,
  // v down: texture x along u, y along v; front normal v x u), its texture
  // made at `px_per_m` texels per metre (capped at 2048 texels per side).
  void AddRect(const Eigen::Vector3d& origin, const Eigen::Vector3d& u, const Eigen::Vector3d& v,
               const TextureMaker& make, double px_per_m, double cell_m = 1.0, int object_id = 0);
  // Same, with a given image (e.g. a photograph) stretched over the rectangle.
  void AddPicture(const Eigen::Vector3d& origin, const Eigen::Vector3d& u, const Eigen::Vector3d& v,
                  const cv::Mat& bgr);

  // The five visible faces (no bottom) of the axis-aligned box [lo, hi] as quads, lit where they
  // stand, faces facing outwards. `top` may differ from the sides; an empty `top` uses `sides`.
  std::vector<DrawQuad> MakeBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                const TextureMaker& sides, double px_per_m,
                                const TextureMaker& top = {}, int object_id = 0);
  void AddBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const TextureMaker& sides,
              double px_per_m, const TextureMaker& top = {});

 private:
  struct Light {
    Eigen::Vector3d position;
    double power;
  };
  struct Occluder {
    double x0, y0, x1, y1, z;
  };
  cv::Mat Lit(const cv::Mat& bgr, const Eigen::Vector3d& origin, const Eigen::Vector3d& u,
              const Eigen::Vector3d& v) const;

  Scene* scene_;
  std::vector<Light> lights_;
  std::vector<Occluder> occluders_;
};

}  // namespace dynorb::synth
