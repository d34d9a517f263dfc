// The synthetic office: a ~6 x 5 x 3 m room modelled on TUM fr3's (desks with monitors and
// keyboards against a partition wall, chairs, a shelf, boxes, posters, a whiteboard), opening
// above the partition onto a large hall beyond the depth sensor's range. Surfaces carry real
// photographs (opencv-doc sample images) where available and procedural textures elsewhere.
//
// World frame: x right, y forward (towards the desks), z up; metres; the room spans
// [0,6] x [0,5] x [0,3]. Deterministic given the seed and the photographs.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "dynorb/synth/renderer.h"
#include "dynorb/synth/scene.h"

namespace dynorb::synth {

// The photographs the office uses (file names in the opencv-doc examples/data directory).
const std::vector<std::string>& OfficePhotoNames();

// Loads photographs by file name. With an empty directory, or for files that cannot be read when
// not strict, a procedural stand-in is returned (and the name recorded in missing()). Strict:
// a missing directory or file throws InputError.
class PhotoLibrary {
 public:
  PhotoLibrary(const std::string& dir, bool strict);
  cv::Mat Get(const std::string& name) const;  // CV_8UC3
  const std::vector<std::string>& missing() const { return missing_; }

 private:
  std::map<std::string, cv::Mat> photos_;
  std::vector<std::string> missing_;
};

struct Office {
  Scene scene;
  Eigen::Vector3d camera_anchor;  // default camera centre of the presets
  Eigen::Vector3d look_at;        // the point the operator films (between the two desks)
  double walk_x0, walk_x1, walk_y0, walk_y1;  // free floor where people walk
  double desk_top_z;
  // Rigid movers, as quads in their own frame (origin at the bottom centre, z up).
  std::vector<DrawQuad> pushed_box;
  Eigen::Vector3d pushed_box_start;  // bottom centre at t = 0
  std::vector<DrawQuad> desk_item;
  Eigen::Vector3d desk_item_start;
};

void BuildOffice(uint64_t seed, const PhotoLibrary& photos, Office* office);

}  // namespace dynorb::synth
