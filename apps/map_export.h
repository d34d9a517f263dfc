// The map at the end of `dynorb run`: its landmarks as a coloured point cloud (`--save-map`,
// OUT/map.ply) and, on sequences with ground-truth masks, how many of them were made on dynamic
// objects (stats.json `map_landmarks_on_dynamic_objects`).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include <nlohmann/json.hpp>

#include "dynamic_labels.h"
#include "dynorb/io/point_cloud_io.h"
#include "dynorb/io/tum_sequence.h"
#include "dynorb/map/landmark_summary.h"

namespace dynorb {

// One colour (red, green, blue) per landmark origin (LandmarkSummary::origin): the sequence's
// colour image of the origin keyframe at its keypoint; grey (128) when the origin is unknown or
// not in the sequence. Throws InputError if an image cannot be read.
std::vector<cv::Vec3b> LandmarkColours(const std::vector<LandmarkOrigin>& origins,
                                       const TumSequence& sequence);

// The landmarks as a point cloud (world frame); with `dynamic_object_id` (one value per landmark,
// OriginTruth::object_id; or empty for none) as an extra per-point property of that name.
PointCloud MapPointCloud(const std::vector<LandmarkSummary>& landmarks,
                         const std::vector<cv::Vec3b>& colours,
                         const std::vector<uint8_t>& dynamic_object_id);

// stats.json's `map_landmarks_on_dynamic_objects` from the check of every landmark's origin.
nlohmann::json MapTruthJson(const OriginTruth& truth, size_t num_landmarks);

}  // namespace dynorb
