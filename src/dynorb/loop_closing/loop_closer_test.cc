#include "dynorb/loop_closing/loop_closer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "dynorb/core/error.h"
#include "dynorb/place_recognition/vocabulary.h"
#include "dynorb/tracking/test_world.h"

namespace dynorb {
namespace {

// A camera in the middle of the feature world's room turns 10 degrees per keyframe, more than
// once around. The map is built as a drifting tracker would build it: keyframe i's estimated pose
// is the true one moved by a drift that grows with i (world_from_cam_est = drift(i) * truth), and
// its new landmarks are placed with that pose; a point seen by one of the last 3 keyframes is
// observed again, otherwise it becomes a new landmark. After 360 degrees the camera sees the
// first keyframes' walls again through new, duplicated and drifted landmarks.
class LoopCloserTest : public ::testing::Test {
 protected:
  LoopCloserTest() : world_(5) {}

  static Rigid3d TrueWorldFromCam(int i) {
    return Rigid3d(
        Eigen::Quaterniond(Eigen::AngleAxisd(i * 10.0 * M_PI / 180.0, Eigen::Vector3d::UnitY())),
        Eigen::Vector3d(0.0, 0.0, 0.5));
  }
  // World-frame error: none for the first 10 keyframes (the place the loop returns to is exact),
  // then 0.2 degree and 4 mm more per keyframe.
  static Rigid3d Drift(int i) {
    const double k = std::max(0, i - 10);
    return Rigid3d(
        Eigen::Quaterniond(Eigen::AngleAxisd(k * 0.2 * M_PI / 180.0, Eigen::Vector3d::UnitY())),
        Eigen::Vector3d(0.004 * k, 0.001 * k, 0.0));
  }

  std::shared_ptr<const Vocabulary> TrainVocabulary() const {
    std::vector<cv::Mat> training;
    for (int i = 0; i < 36; i += 3)
      training.push_back(world_.Observe(TrueWorldFromCam(i), 77 + i)->descriptors());
    VocabularyOptions options;
    options.branching = 8;
    options.levels = 3;
    return std::make_shared<const Vocabulary>(Vocabulary::Train(training, options));
  }

  // Adds keyframe i as described above; returns its id.
  KeyframeId AddKeyframe(MapData* map, int i) {
    std::vector<int> point_ids;
    Keyframe k;
    k.frame_id = static_cast<FrameId>(i * 10);
    k.timestamp_s = i / 3.0;
    k.features = world_.Observe(TrueWorldFromCam(i), 500 + i, 0.5, &point_ids);
    k.cam_from_world = (Drift(i) * TrueWorldFromCam(i)).Inverse();
    const KeyframeId id = map->AddKeyframe(k);
    std::vector<LandmarkId> touched;
    for (size_t kp = 0; kp < point_ids.size(); ++kp) {
      const int p = point_ids[kp];
      auto it = point_landmark_.find(p);
      if (it != point_landmark_.end() && map->HasLandmark(it->second.first) &&
          it->second.second + 3 >= i) {
        map->AddObservation(it->second.first, id, static_cast<int>(kp));
        touched.push_back(it->second.first);
        continue;
      }
      if (!k.features->HasDepth(static_cast<int>(kp))) continue;
      Landmark l;
      l.point_in_world = Drift(i) * world_.points()[p];
      l.reference_keyframe = l.first_keyframe = id;
      const LandmarkId lm = map->AddLandmark(l);
      map->AddObservation(lm, id, static_cast<int>(kp));
      point_landmark_[p] = {lm, i};
      touched.push_back(lm);
    }
    for (LandmarkId lm : touched) {
      map->UpdateLandmarkDescriptor(lm);
      map->UpdateLandmarkGeometry(lm);
    }
    map->UpdateConnections(id);
    return id;
  }

  static double CentreErrorM(const MapData& map, KeyframeId id, int i) {
    return (map.keyframe(id).CameraCenterInWorld() - TrueWorldFromCam(i).translation).norm();
  }

  testing::FeatureWorld world_;
  std::map<int, std::pair<LandmarkId, int>>
      point_landmark_;  // world point -> (landmark, keyframe index)
};

TEST_F(LoopCloserTest, ClosesTheLoopAndRemovesMostOfTheDrift) {
  Map map;
  map.Write([&](MapData& m) { m.SetVocabulary(TrainVocabulary()); });
  LoopClosingOptions options;
  options.global_ba = false;  // the pose graph's result alone (GlobalBundleAdjustmentAfter...)
  LoopCloser closer(world_.sensor(), TrackerOptions(), LocalMapperOptions(), options, &map);
  std::map<KeyframeId, int> index_of;
  LoopStepStats closed;
  int detected_before = 0;
  for (int i = 0; i < 48 && !closed.closed; ++i) {
    const KeyframeId id = map.Write([&](MapData& m) { return AddKeyframe(&m, i); });
    index_of[id] = i;
    const LoopStepStats s = closer.ProcessOne(id);
    if (i < 36) {
      EXPECT_FALSE(s.detected) << "keyframe " << i << ": no place seen before yet";
    }
    detected_before += s.detected ? 1 : 0;
    if (s.closed) closed = s;
  }
  ASSERT_TRUE(closed.closed);
  const int closing_index = index_of.at(closed.keyframe);
  EXPECT_GE(closing_index, 36);  // after a full turn, once consecutive keyframes agreed
  EXPECT_LE(closing_index, 44);
  EXPECT_LE(index_of.at(closed.loop_keyframe), 10);
  EXPECT_GE(closed.inliers, 50);
  EXPECT_GT(closed.fused, 50);
  // The verified pose moved the keyframe by about its drift.
  const double drift_m = ((Drift(closing_index) * TrueWorldFromCam(closing_index)).translation -
                          TrueWorldFromCam(closing_index).translation)
                             .norm();
  EXPECT_NEAR(closed.correction_m, drift_m, 0.5 * drift_m);
  map.Read([&](const MapData& m) {
    EXPECT_EQ(m.correction_epoch(), 1u);
    double worst_before = 0.0, worst_after = 0.0;
    for (const auto& [id, k] : m.keyframes()) {
      const int i = index_of.at(id);
      worst_before = std::max(
          worst_before,
          ((Drift(i) * TrueWorldFromCam(i)).translation - TrueWorldFromCam(i).translation).norm());
      worst_after = std::max(worst_after, CentreErrorM(m, id, i));
    }
    EXPECT_GT(worst_before, 0.1);
    EXPECT_LT(worst_after, worst_before / 3.0)
        << "before " << worst_before << " m, after " << worst_after << " m";
    EXPECT_LT(CentreErrorM(m, closed.keyframe, closing_index), 0.02);
    // Landmarks sit where their reference keyframe sees them (one moved twice, by its
    // neighbourhood's correction and again by its reference keyframe's, would be off by the drift).
    std::vector<double> errors;
    for (const auto& [point, entry] : point_landmark_) {
      if (!m.HasLandmark(entry.first)) continue;
      const Landmark& l = m.landmark(entry.first);
      // Landmarks still referenced to the keyframe that created them: exact before the loop.
      if (!m.HasKeyframe(l.reference_keyframe) || l.reference_keyframe != l.first_keyframe)
        continue;
      const Eigen::Vector3d estimated =
          m.keyframe(l.reference_keyframe).cam_from_world * l.point_in_world;
      const Eigen::Vector3d truth =
          TrueWorldFromCam(index_of.at(l.reference_keyframe)).Inverse() * world_.points()[point];
      errors.push_back((estimated - truth).norm());
    }
    EXPECT_GT(errors.size(), 1000u);
    if (errors.empty()) return 0;
    std::sort(errors.begin(), errors.end());
    // Those seen by the corrected neighbourhood follow it, not their own reference keyframe just
    // outside it, which the pose graph moves a few cm differently (as in ORB-SLAM2).
    EXPECT_LT(errors[errors.size() * 95 / 100], 0.01);
    EXPECT_LT(errors.back(), 0.2);
    // The closing keyframe now shares landmarks with the loop keyframe's side of the map.
    EXPECT_GT(m.keyframe(closed.keyframe).covisibility.count(closed.loop_keyframe) +
                  m.keyframe(closed.loop_keyframe).covisibility.count(closed.keyframe),
              0u);
    return 0;
  });
}

TEST_F(LoopCloserTest, GlobalBundleAdjustmentAfterTheLoopRemovesTheRestInlineOrInTheBackground) {
  std::map<KeyframeId, Eigen::Vector3d> inline_centres;
  for (const bool background : {false, true}) {
    Map map;
    point_landmark_.clear();
    map.Write([&](MapData& m) { m.SetVocabulary(TrainVocabulary()); });
    LoopClosingOptions options;
    options.global_ba_thread = background;
    LoopCloser closer(world_.sensor(), TrackerOptions(), LocalMapperOptions(), options, &map);
    std::map<KeyframeId, int> index_of;
    bool closed = false;
    for (int i = 0; i < 48 && !closed; ++i) {
      const KeyframeId id = map.Write([&](MapData& m) { return AddKeyframe(&m, i); });
      index_of[id] = i;
      closed = closer.ProcessOne(id).closed;
    }
    ASSERT_TRUE(closed);
    closer.WaitForGlobalBa();
    const std::vector<GlobalBaStats> gba = closer.global_ba_stats();
    ASSERT_EQ(gba.size(), 1u);
    EXPECT_TRUE(gba[0].committed);
    EXPECT_EQ(gba[0].keyframes, static_cast<int>(index_of.size()));
    map.Read([&](const MapData& m) {
      EXPECT_EQ(m.correction_epoch(), 2u);  // the loop, then the global BA
      double worst = 0.0;
      for (const auto& [id, k] : m.keyframes())
        worst = std::max(worst, CentreErrorM(m, id, index_of.at(id)));
      // The pose graph alone leaves ~3 cm (ClosesTheLoopAndRemovesMostOfTheDrift); the landmarks'
      // evidence removes the rest. The map's first keyframe and the loop keyframe are exact.
      EXPECT_LT(worst, 0.01) << (background ? "background" : "inline");
      EXPECT_EQ(m.FirstInconsistency(), "");
      for (const auto& [id, k] : m.keyframes()) {
        if (!background) {
          inline_centres[id] = k.CameraCenterInWorld();
        } else {
          EXPECT_EQ(k.CameraCenterInWorld(), inline_centres.at(id)) << "keyframe " << id;
        }
      }
      return 0;
    });
  }
}

TEST_F(LoopCloserTest, DisabledOrWithoutVocabularyNothingHappens) {
  for (const bool disabled : {true, false}) {
    Map map;
    point_landmark_.clear();
    if (disabled) map.Write([&](MapData& m) { m.SetVocabulary(TrainVocabulary()); });
    LoopClosingOptions options;
    options.enabled = !disabled;
    LoopCloser closer(world_.sensor(), TrackerOptions(), LocalMapperOptions(), options, &map);
    for (int i = 0; i < 46; ++i) {
      const KeyframeId id = map.Write([&](MapData& m) { return AddKeyframe(&m, i); });
      EXPECT_FALSE(closer.ProcessOne(id).detected);
    }
    EXPECT_EQ(map.Read([](const MapData& m) { return m.correction_epoch(); }), 0u);
  }
}

TEST(LoopClosingOptions, Validate) {
  LoopClosingOptions o;
  o.consistency = 0;
  EXPECT_THROW(o.Validate(), InputError);
  o = LoopClosingOptions();
  o.global_ba_iterations = 0;
  EXPECT_THROW(o.Validate(), InputError);
}

}  // namespace
}  // namespace dynorb
