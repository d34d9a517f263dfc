// The landmarks' dynamic votes: which landmarks a frame observes moving (LandmarksSeenMoving) and
// how the tracker erases the repeat offenders (TrackerOptions::dynamic_votes_to_erase).
#include <algorithm>

#include <gtest/gtest.h>

#include "dynorb/core/error.h"
#include "dynorb/tracking/dynamic_votes.h"
#include "dynorb/tracking/test_world.h"
#include "dynorb/tracking/tracker.h"

namespace dynorb {
namespace {

// A camera at the origin looking along +z at a wall 3 m away; a mover 1.5 m away covers the
// pixels [220, 420) x [140, 340), and the filter saw keypoints move at (300, 200) and (330, 250).
struct MoverScene {
  PinholeCamera camera = TumFreiburg3Camera();
  cv::Mat depth = cv::Mat(480, 640, CV_32F, cv::Scalar(3.0f));
  std::vector<cv::Point2f> moving = {{300.f, 200.f}, {330.f, 250.f}};
  MoverScene() { depth(cv::Rect(220, 140, 200, 200)).setTo(1.5f); }
  // The point at pixel (u, v) and depth z.
  Eigen::Vector3d At(double u, double v, double z) const { return camera.Unproject({u, v}, z); }
  std::vector<LandmarkId> Seen(const std::vector<Eigen::Vector3d>& points) const {
    std::vector<LandmarkId> ids(points.size());
    for (size_t k = 0; k < ids.size(); ++k) ids[k] = static_cast<LandmarkId>(k + 1);
    std::vector<LandmarkId> seen;
    for (const LandmarkSeenMoving& v : LandmarksSeenMoving(ids, points, Rigid3d::Identity(), camera,
                                                           moving, depth, DynamicVoteOptions()))
      seen.push_back(v.id);
    return seen;
  }
};

TEST(LandmarksSeenMoving, LandmarksBesideAMovingKeypointAtItsDepth) {
  const MoverScene scene;
  const std::vector<Eigen::Vector3d> points = {
      scene.At(300, 200, 1.5),   // 1: at a moving keypoint, on the mover: seen moving
      scene.At(305, 205, 1.55),  // 2: 7 px away, within the depth band: seen moving
      scene.At(330, 258, 1.5),   // 3: 8 px from the second: seen moving
      scene.At(300, 209, 1.5),   // 4: 9 px away (radius 8): not seen
      scene.At(300, 200, 3.0),   // 5: the wall behind the moving keypoint: not seen
      scene.At(300, 200, 1.7),   // 6: 0.2 m behind the mover (band 0.05 + 0.01 z^2): not seen
      scene.At(380, 300, 1.5),   // 7: on the mover, far from every moving keypoint: not seen
      Eigen::Vector3d(0.0, 0.0, -1.0),  // 8: behind the camera: not seen
      scene.At(-50, 240, 1.5),          // 9: outside the image: not seen
  };
  EXPECT_EQ(scene.Seen(points), (std::vector<LandmarkId>{1, 2, 3}));
}

TEST(LandmarksSeenMoving, NothingWithoutDepthOrMovingKeypoints) {
  MoverScene scene;
  const std::vector<Eigen::Vector3d> at_mover = {scene.At(300, 200, 1.5)};
  scene.depth.at<float>(200, 300) = 0.0f;  // no depth measured at the first moving keypoint
  EXPECT_TRUE(scene.Seen(at_mover).empty());
  scene.depth.at<float>(200, 300) = 1.5f;
  EXPECT_EQ(scene.Seen(at_mover).size(), 1u);
  scene.moving.clear();
  EXPECT_TRUE(scene.Seen(at_mover).empty());
  scene.moving = {{-3.f, 900.f}};  // outside the image: ignored
  EXPECT_TRUE(scene.Seen(at_mover).empty());
}

class DynamicVotesTracking : public ::testing::Test {
 protected:
  DynamicVotesTracking() : world_(7) { voting_.dynamic_votes_to_erase = 3; }
  // Frame k of the feature world's path, with the room's true depth. With `moving`, the filter
  // "saw move" every keypoint in kMovingRect (what a mover there would give; the keypoints stay,
  // so the tracker also matches the landmarks there).
  TrackingResult Feed(Tracker& tracker, int k, bool moving) {
    const Rigid3d world_from_cam = testing::FeatureWorld::WorldFromCam(k);
    Frame frame(k, k / 30.0, world_.Observe(world_from_cam, 1000 + k));
    if (moving) {
      for (int i = 0; i < frame.features->size(); ++i) {
        const cv::Point2f& pt = frame.features->keypoint(i).pt;
        if (kMovingRect.contains(cv::Point(static_cast<int>(pt.x), static_cast<int>(pt.y))))
          frame.moving_points.push_back(pt);
      }
      frame.depth_m = world_.RenderDepth(world_from_cam);
    }
    return tracker.ProcessOne(std::move(frame), true);
  }
  const cv::Rect kMovingRect{220, 140, 200, 200};
  testing::FeatureWorld world_;
  TrackerOptions voting_;
};

// Three frames in a row that see the keypoints in the rectangle move erase the landmarks there
// (and only those); a tracker with dynamic_votes_to_erase 0 (the default) erases nothing.
TEST_F(DynamicVotesTracking, ErasesTheLandmarksSeenMovingThreeTimes) {
  Map map;
  Tracker tracker(world_.sensor(), voting_, &map);
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(Feed(tracker, k, false).pose_valid);
  const size_t before = map.Read([](const MapData& m) { return m.NumLandmarks(); });
  std::vector<ErasedLandmark> erased;
  for (int k = 10; k < 13; ++k) {
    const TrackingResult r = Feed(tracker, k, true);
    ASSERT_TRUE(r.pose_valid);
    EXPECT_GT(r.dynamic_votes, 20) << "frame " << k;
    if (k < 12) {
      EXPECT_TRUE(r.erased_as_dynamic.empty()) << "frame " << k;
    }
    erased.insert(erased.end(), r.erased_as_dynamic.begin(), r.erased_as_dynamic.end());
  }
  ASSERT_GT(erased.size(), 20u);
  // Within the rectangle grown by the vote radius (8 px) and the keypoints' noise.
  const cv::Rect grown(kMovingRect.x - 10, kMovingRect.y - 10, kMovingRect.width + 20,
                       kMovingRect.height + 20);
  for (const ErasedLandmark& e : erased) {
    const Eigen::Vector2d& px = e.seen.pixel;
    EXPECT_TRUE(grown.contains(cv::Point2d(px.x(), px.y()))) << px.transpose();
    EXPECT_FALSE(map.Read([&](const MapData& m) { return m.HasLandmark(e.seen.id); }));
    EXPECT_TRUE(e.origin.known);  // Made by a keyframe still in the map.
  }
  // Only the tracker erases here (no mapper, no culling).
  EXPECT_EQ(map.Read([](const MapData& m) { return m.NumLandmarks(); }) + erased.size(), before);

  Map map_off;
  Tracker tracker_off(world_.sensor(), TrackerOptions(), &map_off);
  for (int k = 0; k < 13; ++k) {
    const TrackingResult r = Feed(tracker_off, k, k >= 10);
    EXPECT_EQ(r.dynamic_votes, 0);
    EXPECT_TRUE(r.erased_as_dynamic.empty());
  }
}

// A frame that matches a voted landmark as a pose inlier without seeing it move clears its count:
// with such a frame between two pairs of moving frames, (almost) nothing reaches three votes,
// and the frame after the second pair erases what the first three moving frames in a row erase.
TEST_F(DynamicVotesTracking, AStaticMatchBetweenVotesClearsTheCount) {
  Map map;
  Tracker tracker(world_.sensor(), voting_, &map);
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(Feed(tracker, k, false).pose_valid);
  size_t erased = 0;
  for (int k = 10; k < 15; ++k) {
    const TrackingResult r = Feed(tracker, k, k != 12);
    ASSERT_TRUE(r.pose_valid);
    erased += r.erased_as_dynamic.size();
  }
  const TrackingResult third = Feed(tracker, 15, true);
  EXPECT_GT(third.erased_as_dynamic.size(), 20u);
  EXPECT_LT(erased, third.erased_as_dynamic.size() / 4 + 1);
}

TEST(TrackerOptions, RejectsNegativeDynamicVoteSettings) {
  TrackerOptions o;
  o.dynamic_votes_to_erase = -1;
  EXPECT_THROW(o.Validate(), InputError);
  o = TrackerOptions();
  o.dynamic_votes.band_m = -0.1;
  EXPECT_THROW(o.Validate(), InputError);
}

}  // namespace
}  // namespace dynorb
