#include "dynorb/place_recognition/keyframe_database.h"

#include <gtest/gtest.h>

namespace dynorb {
namespace {

BowVector Bow(std::vector<uint32_t> words) {
  BowVector b;
  for (uint32_t w : words) b.push_back({w, 1.0f / static_cast<float>(words.size())});
  return b;
}

TEST(KeyframeDatabase, QueryRanksBySharedWeightAndForgetsErasedKeyframes) {
  KeyframeDatabase db;
  db.Add(1, Bow({1, 2, 3, 4}));
  db.Add(2, Bow({3, 4, 5, 6}));
  db.Add(3, Bow({1, 2, 3, 5}));
  db.Add(4, Bow({7, 8}));
  const BowVector query = Bow({1, 2, 3, 4});
  std::vector<ScoredKeyframe> r = db.Query(query, 0.0);
  ASSERT_EQ(r.size(), 3u);  // keyframe 4 shares no word
  EXPECT_EQ(r[0].keyframe, 1u);
  EXPECT_NEAR(r[0].score, 1.0, 1e-6);
  EXPECT_EQ(r[0].common_words, 4);
  EXPECT_EQ(r[1].keyframe, 3u);
  EXPECT_NEAR(r[1].score, 0.75, 1e-6);
  EXPECT_EQ(r[2].keyframe, 2u);
  EXPECT_NEAR(r[2].score, 0.5, 1e-6);

  // ORB-SLAM2's rule: at least 80 % of the best keyframe's shared words (4 -> 4 * 0.8 = 3.2 -> 4).
  r = db.Query(query);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].keyframe, 1u);

  // Excluded keyframes neither come back nor set the best count: without 1, keyframe 3 (3 shared
  // words) is the best and 2 (2 words) is below 80 % of it.
  r = db.Query(query, 0.8, {1});
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].keyframe, 3u);

  db.Erase(1);
  EXPECT_FALSE(db.Contains(1));
  r = db.Query(query);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].keyframe, 3u);
  EXPECT_EQ(db.size(), 3u);
}

TEST(KeyframeDatabase, AddingAgainReplacesAndTiesGoToTheLowerId) {
  KeyframeDatabase db;
  db.Add(5, Bow({1, 2}));
  db.Add(2, Bow({1, 2}));
  db.Add(5, Bow({9}));  // replaced: no longer shares words 1 and 2
  std::vector<ScoredKeyframe> r = db.Query(Bow({1, 2}));
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].keyframe, 2u);
  db.Add(1, Bow({1, 2}));
  r = db.Query(Bow({1, 2}));
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].keyframe, 1u);
  EXPECT_EQ(r[1].keyframe, 2u);
  EXPECT_TRUE(db.Query({}).empty());
  db.Erase(42);  // unknown: nothing happens
  EXPECT_EQ(db.size(), 3u);
}

}  // namespace
}  // namespace dynorb
