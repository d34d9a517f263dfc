#include "map_export.h"

#include <map>
#include <stdexcept>

#include "dynorb/dynamic/pixel.h"
#include "dynorb/io/rgbd_image_io.h"

namespace dynorb {

std::vector<cv::Vec3b> LandmarkColours(const std::vector<LandmarkOrigin>& origins,
                                       const TumSequence& sequence) {
  std::map<double, size_t> entry_at;  // rgb stamp -> entry
  for (size_t i = 0; i < sequence.entries().size(); ++i)
    entry_at.emplace(sequence.entries()[i].rgb_timestamp_s, i);
  std::vector<cv::Vec3b> colours(origins.size(), cv::Vec3b(128, 128, 128));
  cv::Mat bgr;  // Of the stamp being visited: one decoded image at a time.
  double bgr_stamp = 0.0;
  bool have_image = false;
  for (size_t i : KnownOriginsByStamp(origins)) {
    const LandmarkOrigin& origin = origins[i];
    if (!have_image || origin.timestamp_s != bgr_stamp) {
      // Keyframe stamps are the entries' rgb stamps; allow for a rounding difference.
      bgr.release();
      auto entry = entry_at.lower_bound(origin.timestamp_s - 1e-6);
      if (entry != entry_at.end() && entry->first <= origin.timestamp_s + 1e-6)
        bgr = LoadColorImage(sequence.ResolvePath(sequence.entries()[entry->second].rgb_path));
      bgr_stamp = origin.timestamp_s;
      have_image = true;
    }
    if (bgr.empty()) continue;
    const cv::Vec3b c = bgr.at<cv::Vec3b>(NearestPixel(origin.keypoint.pt, bgr.size()));
    colours[i] = cv::Vec3b(c[2], c[1], c[0]);
  }
  return colours;
}

PointCloud MapPointCloud(const std::vector<LandmarkSummary>& landmarks,
                         const std::vector<cv::Vec3b>& colours,
                         const std::vector<uint8_t>& dynamic_object_id) {
  if (colours.size() != landmarks.size() ||
      (!dynamic_object_id.empty() && dynamic_object_id.size() != landmarks.size())) {
    throw std::logic_error("MapPointCloud: one colour (and object id) per landmark expected");
  }
  PointCloud cloud;
  cloud.points.reserve(landmarks.size());
  for (const LandmarkSummary& l : landmarks) cloud.points.push_back(l.point_in_world.cast<float>());
  cloud.rgb = colours;
  if (!dynamic_object_id.empty()) cloud.flags.emplace_back("dynamic_object_id", dynamic_object_id);
  return cloud;
}

nlohmann::json MapTruthJson(const OriginTruth& truth, size_t num_landmarks) {
  nlohmann::json by_object = nlohmann::json::object();
  for (const auto& [id, count] : truth.by_object) by_object[std::to_string(id)] = count;
  return {
      {"landmarks", num_landmarks},
      {"origin_known", truth.with_origin},
      {"made_on_dynamic_objects", truth.made_on_objects},
      {"by_object", by_object},
      {"fraction", truth.with_origin > 0
                       ? static_cast<double>(truth.made_on_objects) / truth.with_origin
                       : 0.0},
      {"definition",
       "landmarks of the final map whose keypoint in their oldest observing keyframe lay on a "
       "dynamic object of the masks (moving at that frame or not), of those whose keyframe has a "
       "mask (origin_known); by_object: per id of the masks (synthetic sequences: 1-3 people, "
       "4 the pushed box, 5 the desk item)"}};
}

}  // namespace dynorb
