#include "dynorb/tracking/dynamic_votes.h"

#include <algorithm>
#include <cmath>

namespace dynorb {

std::vector<LandmarkSeenMoving> LandmarksSeenMoving(
    const std::vector<LandmarkId>& ids, const std::vector<Eigen::Vector3d>& points_in_world,
    const Rigid3d& cam_from_world, const PinholeCamera& camera,
    const std::vector<cv::Point2f>& moving_points, const cv::Mat& depth_m,
    const DynamicVoteOptions& options) {
  std::vector<LandmarkSeenMoving> seen;
  if (moving_points.empty() || depth_m.empty() || depth_m.type() != CV_32F ||
      options.radius_px <= 0.0)
    return seen;
  // The moving points with depth, bucketed in cells of radius_px.
  const double cell = options.radius_px;
  const int cols = static_cast<int>(std::ceil(depth_m.cols / cell)) + 1;
  const int rows = static_cast<int>(std::ceil(depth_m.rows / cell)) + 1;
  struct Point {
    float x, y, z;
  };
  std::vector<std::vector<Point>> grid(static_cast<size_t>(cols) * rows);
  for (const cv::Point2f& m : moving_points) {
    const int x = static_cast<int>(std::lround(m.x)), y = static_cast<int>(std::lround(m.y));
    if (x < 0 || y < 0 || x >= depth_m.cols || y >= depth_m.rows) continue;
    const float z = depth_m.at<float>(y, x);
    if (!(z > 0.0f)) continue;
    grid[static_cast<size_t>(y / cell) * cols + static_cast<size_t>(x / cell)].push_back(
        {m.x, m.y, z});
  }
  const double r2 = options.radius_px * options.radius_px;
  for (size_t k = 0; k < ids.size() && k < points_in_world.size(); ++k) {
    const Eigen::Vector3d p = cam_from_world * points_in_world[k];
    if (p.z() <= 0.0) continue;
    const Eigen::Vector2d uv = camera.Project(p);
    if (!camera.InImage(uv)) continue;
    const double band = options.band_m + options.band_rel * p.z() * p.z();
    const int cx = static_cast<int>(uv.x() / cell), cy = static_cast<int>(uv.y() / cell);
    bool moving = false;
    for (int gy = std::max(0, cy - 1); gy <= std::min(rows - 1, cy + 1) && !moving; ++gy) {
      for (int gx = std::max(0, cx - 1); gx <= std::min(cols - 1, cx + 1) && !moving; ++gx) {
        for (const Point& m : grid[static_cast<size_t>(gy) * cols + gx]) {
          const double dx = m.x - uv.x(), dy = m.y - uv.y();
          if (dx * dx + dy * dy <= r2 && std::abs(m.z - p.z()) <= band) {
            moving = true;
            break;
          }
        }
      }
    }
    if (moving) seen.push_back({ids[k], uv});
  }
  return seen;
}

std::vector<ErasedLandmark> ApplyDynamicVotes(const Frame& frame,
                                              const std::vector<LandmarkSeenMoving>& seen,
                                              int votes_to_erase, MapData* map) {
  std::vector<LandmarkId> voted;
  for (const LandmarkSeenMoving& v : seen) voted.push_back(v.id);
  std::sort(voted.begin(), voted.end());
  for (size_t i = 0; i < frame.landmarks.size(); ++i) {
    const LandmarkId lm = frame.landmarks[i];
    if (lm == kNoLandmark || frame.outlier[i] || !map->HasLandmark(lm)) continue;
    if (!std::binary_search(voted.begin(), voted.end(), lm))
      map->landmark(lm).dynamic_votes = 0;  // Seen static.
  }
  std::vector<ErasedLandmark> erased;
  for (const LandmarkSeenMoving& v : seen) {
    if (!map->HasLandmark(v.id)) continue;
    Landmark& l = map->landmark(v.id);
    if (++l.dynamic_votes < votes_to_erase) continue;
    ErasedLandmark e;
    e.seen = v;
    e.origin = OriginOf(*map, l);
    map->EraseLandmark(v.id);
    erased.push_back(e);
  }
  return erased;
}

}  // namespace dynorb
