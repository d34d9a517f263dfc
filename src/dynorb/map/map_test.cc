#include "dynorb/map/map.h"

#include <atomic>
#include <chrono>
#include <limits>
#include <memory>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "dynorb/map/frame_features.h"
#include "dynorb/map/landmark_summary.h"
#include "dynorb/map/place_candidates.h"

namespace dynorb {
namespace {

RgbdSensor Sensor() {
  RgbdSensor s;
  s.camera = TumFreiburg3Camera();
  s.bf = 40.0;
  return s;
}

// n keypoints on a regular lattice, levels cycling 0..3, random descriptors.
std::shared_ptr<const FrameFeatures> MakeFeatures(int n, uint64_t seed, float depth_m = 2.0f) {
  std::mt19937_64 rng(seed);
  OrbFeatures orb;
  orb.descriptors = cv::Mat(n, 32, CV_8U);
  for (int i = 0; i < n; ++i) {
    cv::KeyPoint kp(cv::Point2f(20.0f + 37.0f * (i % 16), 20.0f + 29.0f * (i / 16)), 31.0f, 0.0f, 1.0f, i % 4);
    orb.keypoints.push_back(kp);
    for (int b = 0; b < 32; ++b) orb.descriptors.at<uint8_t>(i, b) = static_cast<uint8_t>(rng());
  }
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(depth_m));
  depth(cv::Rect(0, 0, 100, 100)).setTo(0.0f);  // A hole without depth.
  return std::make_shared<const FrameFeatures>(orb, depth, Sensor(), ScaleLevels(8, 1.2));
}

TEST(FrameFeatures, DepthURightAndObservation) {
  const auto f = MakeFeatures(200, 1);
  ASSERT_EQ(f->size(), 200);
  EXPECT_FALSE(f->HasDepth(0));  // (20, 20) lies in the hole.
  const int i = 50;
  ASSERT_TRUE(f->HasDepth(i));
  EXPECT_FLOAT_EQ(f->depth(i), 2.0f);
  EXPECT_NEAR(f->u_right(i), f->keypoint(i).pt.x - 40.0 / 2.0, 1e-4);
  const KeypointObservation obs = f->Observation(i);
  EXPECT_NEAR(obs.information, 1.0 / std::pow(1.2, 2 * (i % 4)), 1e-12);
  // The depth's weight comes from the sensor (default 0.15 px of disparity), not from the level.
  EXPECT_NEAR(obs.disparity_information, 1.0 / (0.15 * 0.15), 1e-9);
  EXPECT_TRUE(obs.IsStereo());
  EXPECT_FALSE(f->Observation(0).IsStereo());
  const Eigen::Vector3d p = f->PointInCam(i, Sensor().camera);
  EXPECT_NEAR(p.z(), 2.0, 1e-9);
  EXPECT_LT((Sensor().camera.Project(p) - obs.uv).norm(), 1e-4);
  // disparity_sigma_px 0: ORB-SLAM2's u_r residual (no disparity information).
  RgbdSensor orb_slam2 = Sensor();
  orb_slam2.disparity_sigma_px = 0.0;
  OrbFeatures one;
  one.keypoints.push_back(f->keypoint(i));
  one.descriptors = cv::Mat(1, 32, CV_8U, cv::Scalar(0));
  const FrameFeatures plain(one, std::vector<float>{2.0f}, orb_slam2, ScaleLevels(8, 1.2));
  EXPECT_EQ(plain.Observation(0).disparity_information, 0.0);
  EXPECT_TRUE(plain.Observation(0).IsStereo());
}

TEST(FrameFeatures, NearbyMinDepthIsTheNearestMeasurementAroundTheKeypoint) {
  OrbFeatures orb;
  orb.descriptors = cv::Mat(4, 32, CV_8U, cv::Scalar(0));
  for (const cv::Point2f& p : {cv::Point2f(100, 100), cv::Point2f(300, 200), cv::Point2f(2, 2), cv::Point2f(500, 400)}) {
    orb.keypoints.emplace_back(p, 31.0f, 0.0f, 1.0f, 0);
  }
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(3.0f));
  depth.at<float>(100, 100) = 0.0f;                            // A hole at the keypoint ...
  depth.at<float>(100 + 5, 100 - 5) = 1.5f;                    // ... a nearer surface at the window's corner,
  depth.at<float>(100 + 6, 100) = 0.5f;                        // and one just outside it.
  depth(cv::Rect(295, 195, 11, 11)).setTo(0.0f);               // No measurement in the whole window.
  depth.at<float>(0, 0) = 2.0f;                                // Window clipped at the border.
  depth(cv::Rect(0, 1, 8, 7)).setTo(std::numeric_limits<float>::quiet_NaN());
  const FrameFeatures f(orb, depth, Sensor(), ScaleLevels(8, 1.2));
  EXPECT_FALSE(f.HasDepth(0));
  EXPECT_FLOAT_EQ(f.nearby_min_depth(0), 1.5f);
  EXPECT_FLOAT_EQ(f.nearby_min_depth(1), 0.0f);
  EXPECT_FLOAT_EQ(f.nearby_min_depth(2), 2.0f);  // NaN is no measurement.
  EXPECT_FLOAT_EQ(f.nearby_min_depth(3), 3.0f);
  EXPECT_FLOAT_EQ(f.depth(3), 3.0f);
  EXPECT_FLOAT_EQ(f.far_depth(), 3.0f);  // 95th percentile of the valid depths.
  // Per-keypoint depths (no image): nothing is known around the keypoints.
  const FrameFeatures g(orb, std::vector<float>{1.0f, 1.0f, 1.0f, 1.0f}, Sensor(), ScaleLevels(8, 1.2));
  EXPECT_FLOAT_EQ(g.nearby_min_depth(0), 0.0f);
  EXPECT_FLOAT_EQ(g.far_depth(), 0.0f);
}

TEST(FrameFeatures, FarDepthIsTheNinetyFifthPercentileOfTheMeasuredDepths) {
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(0.0f));
  // Depth rises linearly over the rows 0..399 (1 m .. 4.99 m); the rest measured nothing.
  for (int y = 0; y < 400; ++y) depth.row(y).setTo(1.0f + 0.01f * static_cast<float>(y));
  const FrameFeatures f(OrbFeatures{}, depth, Sensor(), ScaleLevels(8, 1.2));
  EXPECT_NEAR(f.far_depth(), 1.0f + 0.01f * 0.95f * 400.0f, 0.05f);
  const FrameFeatures none(OrbFeatures{}, cv::Mat(480, 640, CV_32F, cv::Scalar(0.0f)), Sensor(), ScaleLevels(8, 1.2));
  EXPECT_FLOAT_EQ(none.far_depth(), 0.0f);
}

TEST(FrameFeatures, AreaQueryMatchesBruteForce) {
  const auto f = MakeFeatures(300, 2);
  for (double r : {5.0, 30.0, 80.0}) {
    for (int min_level : {0, 2}) {
      const std::vector<int> got = f->FeaturesInArea(300.0, 200.0, r, min_level, 2);
      std::vector<int> want;
      for (int i = 0; i < f->size(); ++i) {
        const cv::KeyPoint& kp = f->keypoint(i);
        const double dx = kp.pt.x - 300.0, dy = kp.pt.y - 200.0;
        if (dx * dx + dy * dy <= r * r && kp.octave >= min_level &&
            kp.octave <= 2) {
          want.push_back(i);
        }
      }
      EXPECT_EQ(got, want) << "r=" << r << " min_level=" << min_level;
    }
  }
}

class MapDataTest : public ::testing::Test {
 protected:
  // Keyframes 0, 1, 2; landmarks: 35 seen by 0-1, 15 by 1-2, 5 by all three (so 0-1 share 40,
  // 1-2 share 20, 0-2 share 5).
  void SetUp() override {
    for (int k = 0; k < 3; ++k) {
      Keyframe kf;
      kf.features = MakeFeatures(100, 10 + k);
      kf.cam_from_world = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.1 * k, 0, 0));
      ids_.push_back(map_.AddKeyframe(kf));
    }
    auto add = [&](std::vector<int> kfs, int count) {
      for (int c = 0; c < count; ++c) {
        Landmark lm;
        lm.point_in_world = Eigen::Vector3d(0.01 * next_index_, 0.0, 2.0);
        const LandmarkId id = map_.AddLandmark(lm);
        for (int k : kfs) map_.AddObservation(id, ids_[k], next_index_);
        map_.UpdateLandmarkGeometry(id);
        map_.UpdateLandmarkDescriptor(id);
        ++next_index_;
      }
    };
    add({0, 1}, 35);
    add({1, 2}, 15);
    add({0, 2}, 0);
    add({0, 1, 2}, 5);
    for (KeyframeId id : ids_) map_.UpdateConnections(id);
  }
  MapData map_;
  std::vector<KeyframeId> ids_;
  int next_index_ = 0;
};

TEST_F(MapDataTest, CovisibilityAndSpanningTree) {
  const Keyframe& k1 = map_.keyframe(ids_[1]);
  EXPECT_EQ(k1.covisibility.at(ids_[0]), 40);
  EXPECT_EQ(k1.covisibility.at(ids_[2]), 20);
  EXPECT_EQ(k1.ordered_covisibles, (std::vector<KeyframeId>{ids_[0], ids_[2]}));
  // 0-2 share only 5 (< 15): no edge, since both have stronger edges.
  EXPECT_EQ(map_.keyframe(ids_[0]).covisibility.count(ids_[2]), 0u);
  EXPECT_EQ(map_.keyframe(ids_[1]).parent, ids_[0]);
  EXPECT_EQ(map_.keyframe(ids_[2]).parent, ids_[1]);
  EXPECT_EQ(map_.BestCovisibles(ids_[1], 1), (std::vector<KeyframeId>{ids_[0]}));
  // Every keypoint but those in the depth hole has depth: 3 views with depth weigh 6.
  EXPECT_EQ(map_.NumTrackedLandmarks(ids_[1], 6), 5);
  // Keypoint 0 lies in the depth hole in keyframes 0 and 1: two observations without depth.
  const LandmarkId hole = map_.keyframe(ids_[0]).landmarks[0];
  EXPECT_EQ(map_.WeightedObservations(hole), 1 + 1);
  EXPECT_EQ(map_.WeightedObservations(map_.keyframe(ids_[0]).landmarks[3]), 2 + 2);  // x = 131: depth
}

TEST_F(MapDataTest, EraseObservationDropsUnderObservedLandmark) {
  const LandmarkId lm = map_.keyframe(ids_[0]).landmarks[0];
  ASSERT_NE(lm, kNoLandmark);
  map_.EraseObservation(lm, ids_[0]);
  EXPECT_FALSE(map_.HasLandmark(lm));  // 1 observation left: erased.
  EXPECT_EQ(map_.keyframe(ids_[1]).landmarks[0], kNoLandmark);
}

TEST_F(MapDataTest, SummaryGivesEachLandmarkItsOldestKeyframeStillInTheMap) {
  std::vector<LandmarkSummary> all = SummarizeLandmarks(map_);
  ASSERT_EQ(all.size(), map_.NumLandmarks());
  for (const LandmarkSummary& s : all) {
    const Landmark& l = map_.landmark(s.id);
    EXPECT_EQ(s.point_in_world, l.point_in_world);
    EXPECT_EQ(s.num_observations, l.NumObservations());
    ASSERT_TRUE(s.origin.known);
    const auto& [first_kf, index] = *l.observations.begin();
    EXPECT_EQ(s.origin.keyframe, first_kf);
    EXPECT_EQ(s.origin.timestamp_s, map_.keyframe(first_kf).timestamp_s);
    EXPECT_EQ(s.origin.keypoint.pt, map_.keyframe(first_kf).features->keypoint(index).pt);
  }
  EXPECT_EQ(all[40].origin.keyframe, ids_[1]);  // seen by keyframes 1 and 2
  map_.EraseKeyframe(ids_[1]);
  all = SummarizeLandmarks(map_);
  int moved = 0;
  for (const LandmarkSummary& s : all) {
    ASSERT_TRUE(s.origin.known);
    EXPECT_NE(s.origin.keyframe, ids_[1]);
    moved += s.origin.keyframe == ids_[2] ? 1 : 0;
  }
  EXPECT_GT(moved, 0);  // the 1-2 landmarks that kept an observation now come from keyframe 2
}

TEST(LandmarkSummary, KnownOriginsInStampOrderTiesByIndex) {
  std::vector<LandmarkOrigin> origins(5);
  const double stamps[] = {2.0, 1.0, 0.5, 1.0, 3.0};
  for (int i = 0; i < 5; ++i) {
    origins[i].known = i != 2;
    origins[i].timestamp_s = stamps[i];
  }
  EXPECT_EQ(KnownOriginsByStamp(origins), (std::vector<size_t>{1, 3, 0, 4}));
  EXPECT_TRUE(KnownOriginsByStamp({}).empty());
}

TEST_F(MapDataTest, ReplaceLandmarkMovesObservations) {
  const LandmarkId a = map_.keyframe(ids_[0]).landmarks[0];   // seen by 0, 1
  const LandmarkId b = map_.keyframe(ids_[1]).landmarks[40];  // seen by 1, 2
  map_.ReplaceLandmark(a, b);
  EXPECT_FALSE(map_.HasLandmark(a));
  const Landmark& l = map_.landmark(b);
  EXPECT_EQ(l.NumObservations(), 3);
  EXPECT_EQ(map_.keyframe(ids_[0]).landmarks[0], b);
  EXPECT_EQ(map_.keyframe(ids_[1]).landmarks[0], kNoLandmark);  // Kf 1 already saw b elsewhere.
  EXPECT_EQ(l.descriptor.cols, 32);
}

TEST_F(MapDataTest, EraseKeyframeReparentsAndCleans) {
  const Rigid3d pose1 = map_.keyframe(ids_[1]).cam_from_world;
  map_.EraseKeyframe(ids_[1]);
  EXPECT_FALSE(map_.HasKeyframe(ids_[1]));
  EXPECT_LT((map_.ResolveKeyframePose(ids_[1]).translation - pose1.translation).norm(), 1e-12);
  // The erased pose follows its parent when the parent moves (e.g. after bundle adjustment).
  map_.keyframe(ids_[0]).cam_from_world.translation += Eigen::Vector3d(0.5, 0, 0);
  EXPECT_LT((map_.ResolveKeyframePose(ids_[1]).translation - pose1.translation - Eigen::Vector3d(0.5, 0, 0)).norm(),
            1e-12);
  EXPECT_EQ(map_.keyframe(ids_[2]).parent, ids_[0]);
  EXPECT_EQ(map_.keyframe(ids_[0]).covisibility.count(ids_[1]), 0u);
  for (const auto& [id, lm] : map_.landmarks()) {
    EXPECT_EQ(lm.observations.count(ids_[1]), 0u);
    ASSERT_GE(lm.NumObservations(), 1);
    if (lm.NumObservations() == 1) {  // Only a depth-backed single observation may remain.
      const auto& [kf, index] = *lm.observations.begin();
      EXPECT_TRUE(map_.keyframe(kf).features->HasDepth(index));
    }
  }
  map_.EraseKeyframe(ids_[0]);  // The root is never erased.
  EXPECT_TRUE(map_.HasKeyframe(ids_[0]));
}

TEST_F(MapDataTest, AnEdgeDroppedByUpdateConnectionsLeavesBothSidesOrders) {
  EXPECT_EQ(map_.FirstInconsistency(), "");
  // Keyframe 2 stops seeing what it shared with keyframe 1 (e.g. fused away by loop closing).
  for (int index = 35; index < 55; ++index) {
    const LandmarkId lm = map_.keyframe(ids_[2]).landmarks[index];
    if (lm != kNoLandmark) map_.EraseObservation(lm, ids_[2]);
  }
  map_.UpdateConnections(ids_[2]);
  EXPECT_EQ(map_.keyframe(ids_[1]).covisibility.count(ids_[2]), 0u);
  EXPECT_EQ(map_.BestCovisibles(ids_[1], 10), (std::vector<KeyframeId>{ids_[0]}));
  EXPECT_EQ(map_.FirstInconsistency(), "");
  map_.EraseKeyframe(ids_[2]);
  EXPECT_EQ(map_.BestCovisibles(ids_[1], 10), (std::vector<KeyframeId>{ids_[0]}));
  EXPECT_EQ(map_.FirstInconsistency(), "");
}

TEST_F(MapDataTest, ALandmarkMovesWithTheKeyframeItFollows) {
  std::map<KeyframeId, Rigid3d> before, after;
  for (const auto& [id, k] : map_.keyframes()) before[id] = after[id] = k.cam_from_world;
  // Keyframe 1 turns 90 degrees about y and moves; keyframe 0 moves 1 m along x.
  after[ids_[1]] =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY())),
              Eigen::Vector3d(0.3, -0.2, 0.1));
  after[ids_[0]].translation += Eigen::Vector3d(-1.0, 0, 0);  // camera centre +1 m in x
  const LandmarkId lm = map_.keyframe(ids_[1]).landmarks[3];  // seen by 0 and 1, reference 0
  ASSERT_NE(lm, kNoLandmark);
  const Eigen::Vector3d world = map_.landmark(lm).point_in_world;
  ASSERT_EQ(map_.landmark(lm).reference_keyframe, ids_[0]);
  // By default it follows its reference keyframe: same point in keyframe 0's camera.
  ASSERT_TRUE(map_.MoveLandmarkWithKeyframe(lm, before, after));
  EXPECT_LT((map_.landmark(lm).point_in_world - (world + Eigen::Vector3d(1.0, 0, 0))).norm(),
            1e-12);
  // Told to follow keyframe 1: the same point in keyframe 1's camera before and after.
  const Eigen::Vector3d moved = map_.landmark(lm).point_in_world;
  ASSERT_TRUE(map_.MoveLandmarkWithKeyframe(lm, before, after, ids_[1]));
  EXPECT_LT(
      (after.at(ids_[1]) * map_.landmark(lm).point_in_world - before.at(ids_[1]) * moved).norm(),
      1e-12);
  // A keyframe that is gone: its first observer (keyframe 0) instead.
  map_.landmark(lm).point_in_world = world;
  ASSERT_TRUE(map_.MoveLandmarkWithKeyframe(lm, before, after, ids_[2] + 100));
  EXPECT_LT((map_.landmark(lm).point_in_world - (world + Eigen::Vector3d(1.0, 0, 0))).norm(),
            1e-12);
}

TEST_F(MapDataTest, FirstInconsistencyNamesABrokenLink) {
  map_.keyframe(ids_[1]).ordered_covisibles.push_back(ids_[1] + 7);
  EXPECT_NE(map_.FirstInconsistency().find("keyframe 1"), std::string::npos)
      << map_.FirstInconsistency();
}

TEST(MapData, KeepsThePosesBeforeTheLastCorrection) {
  MapData map;
  EXPECT_TRUE(map.poses_before_correction().empty());
  for (int e = 1; e <= 3; ++e) {
    std::map<KeyframeId, Rigid3d> before;
    before[0] = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(e, 0, 0));
    map.NoteCorrection(before);
  }
  EXPECT_EQ(map.correction_epoch(), 3u);
  EXPECT_EQ(map.poses_before_correction().at(0).translation.x(), 3.0);
}

// A correction waits for the frame being tracked, and a frame does not begin while a correction
// waits (otherwise back-to-back frames could hold it off for ever). Sleeps only give the other
// thread a chance to do what it must not: they cannot make a correct gate fail.
TEST(Map, CorrectionsWaitForTheFrameInProgress) {
  Map map;
  std::atomic<bool> corrected{false}, second_frame_began{false}, corrected_before_second{false};
  std::thread corrector, second_frame;
  {
    const Map::FrameScope frame = map.BeginFrame();
    corrector = std::thread([&] {
      map.Correct([&](MapData& data) {
        data.NoteCorrection({});
        corrected = true;
        return 0;
      });
    });
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (map.corrections_waiting() == 0 && !corrected &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::yield();
    }
    EXPECT_EQ(map.corrections_waiting(), 1);
    second_frame = std::thread([&] {
      const Map::FrameScope next = map.BeginFrame();
      corrected_before_second = corrected.load();
      second_frame_began = true;
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    EXPECT_FALSE(corrected);
    EXPECT_FALSE(second_frame_began);
    // The frame still reads and writes the map: the waiting correction does not hold the lock.
    EXPECT_EQ(map.Read([](const MapData& d) { return d.correction_epoch(); }), 0u);
    map.Write([](MapData& d) { return d.AddLandmark(Landmark()); });
  }
  corrector.join();
  second_frame.join();
  EXPECT_TRUE(corrected);
  EXPECT_TRUE(corrected_before_second);
  EXPECT_EQ(map.Read([](const MapData& d) { return d.correction_epoch(); }), 1u);
  EXPECT_EQ(map.corrections_waiting(), 0);
}

TEST(Map, ReadWriteUnderOneLock) {
  Map map;
  const KeyframeId id = map.Write([](MapData& d) {
    Keyframe kf;
    kf.features = MakeFeatures(10, 5);
    return d.AddKeyframe(kf);
  });
  EXPECT_EQ(map.Read([](const MapData& d) { return d.NumKeyframes(); }), 1u);
  EXPECT_EQ(id, 0u);
}

// Place recognition in the map: keyframes get their bag of words and enter the database; a
// place seen by two covisible keyframes is one group, represented by its best keyframe.
TEST(MapData, PlaceCandidatesGroupCovisibleKeyframesAndForgetErasedOnes) {
  const auto place_a = MakeFeatures(200, 11), place_b = MakeFeatures(200, 12),
             place_c = MakeFeatures(200, 13);
  VocabularyOptions vo;
  vo.branching = 8;
  vo.levels = 3;
  MapData map;
  map.SetVocabulary(std::make_shared<const Vocabulary>(Vocabulary::Train(
      {place_a->descriptors(), place_b->descriptors(), place_c->descriptors()}, vo)));
  Keyframe k;
  k.features = place_a;
  const KeyframeId a0 = map.AddKeyframe(k), a1 = map.AddKeyframe(k);
  k.features = place_b;
  const KeyframeId b = map.AddKeyframe(k);
  k.features = place_c;
  const KeyframeId c = map.AddKeyframe(k);
  EXPECT_EQ(map.keyframe_database().size(), 4u);
  EXPECT_FALSE(map.keyframe(a0).bow.empty());
  for (int i = 0; i < 30; ++i) {  // a0 and a1 share 30 landmarks: covisible
    const LandmarkId lm = map.AddLandmark(Landmark());
    map.AddObservation(lm, a0, i);
    map.AddObservation(lm, a1, i);
  }
  map.UpdateConnections(a0);
  map.UpdateConnections(a1);
  const BowVector query = map.vocabulary()->Transform(place_a->descriptors());
  std::vector<ScoredKeyframe> found = PlaceCandidates(map, query);
  ASSERT_EQ(found.size(), 1u);             // b and c share few words; a0 and a1 are one place
  EXPECT_EQ(found[0].keyframe, a0);        // equal scores: the lower id
  EXPECT_NEAR(found[0].score, 2.0, 1e-5);  // accumulated over the group
  found = PlaceCandidates(map, query, {a0});
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].keyframe, a1);
  found = PlaceCandidates(map, map.vocabulary()->Transform(place_c->descriptors()));
  ASSERT_FALSE(found.empty());
  EXPECT_EQ(found[0].keyframe, c);
  map.EraseKeyframe(a1);
  EXPECT_EQ(map.keyframe_database().size(), 3u);
  EXPECT_FALSE(map.keyframe_database().Contains(a1));
  EXPECT_TRUE(map.keyframe_database().Contains(b));
}

}  // namespace
}  // namespace dynorb
