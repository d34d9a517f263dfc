#include "dynorb/place_recognition/vocabulary.h"
#include "dynorb/place_recognition/builtin_vocabulary.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <set>

#include "dynorb/core/error.h"
#include "dynorb/core/test_expect_error.h"

namespace dynorb {
namespace {

cv::Mat RandomPrototypes(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  cv::Mat p(n, 32, CV_8UC1);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < 32; ++c) p.at<uint8_t>(r, c) = static_cast<uint8_t>(rng() & 0xff);
  }
  return p;
}

// `copies` noisy copies (up to `flips` random bits flipped) of each listed prototype row.
cv::Mat NoisyCopies(const cv::Mat& prototypes, const std::vector<int>& which, int copies, int flips,
                    std::mt19937* rng) {
  cv::Mat out;
  for (int p : which) {
    for (int c = 0; c < copies; ++c) {
      cv::Mat row = prototypes.row(p).clone();
      for (int f = 0; f < flips; ++f) {
        const int bit = static_cast<int>((*rng)() % 256);
        row.at<uint8_t>(0, bit / 8) ^= static_cast<uint8_t>(1u << (bit % 8));
      }
      out.push_back(row);
    }
  }
  return out;
}

struct Clustered {
  cv::Mat prototypes;
  std::vector<cv::Mat> images;
};

// Eight well-separated prototypes (random 256-bit strings differ in ~128 bits); image i holds
// copies of prototype 0 (in every image) and of prototype 1 + i % 7.
Clustered EightClusters() {
  Clustered c;
  c.prototypes = RandomPrototypes(8, 7);
  std::mt19937 rng(11);
  for (int i = 0; i < 14; ++i)
    c.images.push_back(NoisyCopies(c.prototypes, {0, 1 + i % 7}, 20, 8, &rng));
  return c;
}

VocabularyOptions Flat(int branching) {
  VocabularyOptions o;
  o.branching = branching;
  o.levels = 1;
  return o;
}

TEST(Vocabulary, SeparatedClustersBecomeOneWordEach) {
  const Clustered c = EightClusters();
  const Vocabulary v = Vocabulary::Train(c.images, Flat(8));
  EXPECT_EQ(v.NumWords(), 8);
  std::mt19937 rng(99);
  std::set<uint32_t> words;
  for (int p = 0; p < 8; ++p) {
    const cv::Mat copies = NoisyCopies(c.prototypes, {p}, 30, 10, &rng);
    const uint32_t w = v.Word(c.prototypes.ptr<uint8_t>(p));
    for (int r = 0; r < copies.rows; ++r)
      EXPECT_EQ(v.Word(copies.ptr<uint8_t>(r)), w) << "prototype " << p;
    words.insert(w);
  }
  EXPECT_EQ(words.size(), 8u);
}

TEST(Vocabulary, ClustersAnEvenSubsampleButCountsEveryImage) {
  const Clustered c = EightClusters();  // 14 images x 40 descriptors
  VocabularyOptions o = Flat(8);
  o.max_cluster_descriptors = 100;  // every 6th descriptor is clustered
  const Vocabulary v = Vocabulary::Train(c.images, o);
  EXPECT_EQ(v.NumWords(), 8);
  EXPECT_NEAR(v.idf(v.Word(c.prototypes.ptr<uint8_t>(1))), std::log(14.0 / 2.0), 1e-6);
  o.max_cluster_descriptors = 4;
  testing::ExpectInputError([&] { o.Validate(); }, "max_cluster_descriptors");
}

TEST(Vocabulary, IdfIsZeroForAWordInEveryImageAndLogNForARareOne) {
  const Clustered c = EightClusters();
  const Vocabulary v = Vocabulary::Train(c.images, Flat(8));
  EXPECT_FLOAT_EQ(v.idf(v.Word(c.prototypes.ptr<uint8_t>(0))), 0.0f);
  // Prototype 1 is in images 0 and 7 of 14.
  EXPECT_NEAR(v.idf(v.Word(c.prototypes.ptr<uint8_t>(1))), std::log(14.0 / 2.0), 1e-6);
}

TEST(Vocabulary, TransformIsNormalisedAndScoresSamePlaceHigh) {
  const Clustered c = EightClusters();
  const Vocabulary v = Vocabulary::Train(c.images, Flat(8));
  std::mt19937 rng(5);
  const BowVector a = v.Transform(NoisyCopies(c.prototypes, {0, 2, 3}, 10, 6, &rng));
  const BowVector a2 = v.Transform(NoisyCopies(c.prototypes, {3, 2, 0}, 12, 6, &rng));
  const BowVector b = v.Transform(NoisyCopies(c.prototypes, {0, 5, 6}, 10, 6, &rng));
  ASSERT_EQ(a.size(), 2u);  // prototype 0's word has idf 0 and is dropped
  double sum = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    sum += a[i].weight;
    if (i > 0) {
      EXPECT_LT(a[i - 1].word, a[i].word);
    }
  }
  EXPECT_NEAR(sum, 1.0, 1e-6);
  EXPECT_NEAR(BowScore(a, a), 1.0, 1e-6);
  EXPECT_NEAR(BowScore(a, a2), 1.0, 1e-6);  // same words, same proportions
  EXPECT_NEAR(BowScore(a, b), 0.0, 1e-9);   // only the uninformative word in common
  EXPECT_TRUE(v.Transform(cv::Mat()).empty());
}

// Six images of ten prototypes each (60 in all), five noisy copies of every prototype.
std::vector<cv::Mat> SixPlaces() {
  const cv::Mat prototypes = RandomPrototypes(60, 3);
  std::mt19937 rng(4);
  std::vector<cv::Mat> images;
  for (int i = 0; i < 6; ++i) {
    std::vector<int> which;
    for (int p = i * 10; p < i * 10 + 10; ++p) which.push_back(p);
    images.push_back(NoisyCopies(prototypes, which, 5, 4, &rng));
  }
  return images;
}

TEST(Vocabulary, TreeWithSeveralLevelsReachesEveryLeaf) {
  const std::vector<cv::Mat> images = SixPlaces();
  VocabularyOptions o;
  o.branching = 4;
  o.levels = 3;
  const Vocabulary v = Vocabulary::Train(images, o);
  EXPECT_GT(v.NumWords(), 16);
  EXPECT_LE(v.NumWords(), 64);
  std::set<uint32_t> words;
  for (const cv::Mat& image : images) {
    for (int r = 0; r < image.rows; ++r) words.insert(v.Word(image.ptr<uint8_t>(r)));
  }
  EXPECT_EQ(static_cast<int>(words.size()),
            v.NumWords());  // every word is some training descriptor's
  EXPECT_LT(*words.rbegin(), static_cast<uint32_t>(v.NumWords()));
}

TEST(Vocabulary, TrainingIsReproducibleAndTheBinaryFormRoundTrips) {
  const Clustered c = EightClusters();
  VocabularyOptions o;
  o.branching = 3;
  o.levels = 2;
  const Vocabulary v = Vocabulary::Train(c.images, o);
  EXPECT_EQ(Vocabulary::Train(c.images, o).ToBytes(), v.ToBytes());
  const std::string path = ::testing::TempDir() + "/vocabulary_test.bin";
  v.Save(path);
  const Vocabulary back = Vocabulary::Load(path);
  std::remove(path.c_str());
  EXPECT_EQ(back.ToBytes(), v.ToBytes());
  EXPECT_EQ(back.NumWords(), v.NumWords());
  EXPECT_EQ(back.branching(), 3);
  EXPECT_EQ(back.levels(), 2);
  for (const cv::Mat& image : c.images) {
    for (int r = 0; r < image.rows; ++r)
      EXPECT_EQ(back.Word(image.ptr<uint8_t>(r)), v.Word(image.ptr<uint8_t>(r)));
  }
}

TEST(Vocabulary, BadFilesAndOptionsAreInputErrors) {
  const Clustered c = EightClusters();
  const std::string bytes = Vocabulary::Train(c.images, Flat(8)).ToBytes();
  testing::ExpectInputError([&] { Vocabulary::FromBytes("hello", "v.bin"); },
                            "v.bin: not a dynorb vocabulary");
  std::string flipped = bytes;
  flipped[40] ^= 1;
  testing::ExpectInputError([&] { Vocabulary::FromBytes(flipped, "v.bin"); },
                            "v.bin: vocabulary file is corrupt");
  testing::ExpectInputError(
      [&] { Vocabulary::FromBytes(bytes.substr(0, bytes.size() - 20), "v.bin"); }, "corrupt");
  testing::ExpectInputError([&] { Vocabulary::Load("/nonexistent/v.bin"); },
                            "/nonexistent/v.bin: cannot open");
  testing::ExpectInputError(
      [&] { Vocabulary::Train({cv::Mat(3, 32, CV_8UC1, cv::Scalar(1))}, Flat(8)); },
      "at least 8 descriptors, got 3");
  testing::ExpectInputError([&] { Vocabulary::Train({cv::Mat(30, 16, CV_8UC1)}, Flat(8)); },
                            "32 columns");
  // A checksum-valid file whose branching field is out of range.
  std::string inconsistent = bytes.substr(0, bytes.size() - 8);
  inconsistent[8] = 99;
  uint64_t h = 1469598103934665603ULL;
  for (char ch : inconsistent) h = (h ^ static_cast<uint8_t>(ch)) * 1099511628211ULL;
  for (int i = 0; i < 8; ++i) inconsistent.push_back(static_cast<char>((h >> (8 * i)) & 0xff));
  testing::ExpectInputError([&] { Vocabulary::FromBytes(inconsistent, "v.bin"); },
                            "v.bin: inconsistent vocabulary: branching or levels");
  VocabularyOptions o;
  o.branching = 1;
  testing::ExpectInputError([&] { o.Validate(); }, "branching");
  o.branching = 10;
  o.levels = 9;
  testing::ExpectInputError([&] { o.Validate(); }, "levels");
}

// `bytes` (a vocabulary file) with `edit` applied to its fields and the checksum sealed again: a
// hand-edited file that only the consistency checks can catch.
std::string Resealed(const std::string& bytes, const std::function<void(std::string*)>& edit) {
  std::string fields = bytes.substr(0, bytes.size() - 8);
  edit(&fields);
  uint64_t h = 1469598103934665603ULL;
  for (char ch : fields) h = (h ^ static_cast<uint8_t>(ch)) * 1099511628211ULL;
  for (int i = 0; i < 8; ++i) fields.push_back(static_cast<char>((h >> (8 * i)) & 0xff));
  return fields;
}

void PutFloat(std::string* bytes, size_t at, float value) { std::memcpy(&(*bytes)[at], &value, 4); }

// Session-55 review: a tree deeper than its levels, word weights no training gives, every weight
// 0, a file larger than its header says, training on one image.
TEST(Vocabulary, HandEditedOrUselessVocabulariesAreRefused) {
  const std::vector<cv::Mat> images = SixPlaces();
  VocabularyOptions o;
  o.branching = 4;
  o.levels = 3;
  const std::string bytes = Vocabulary::Train(images, o).ToBytes();
  ASSERT_NO_THROW(Vocabulary::FromBytes(bytes, "v.bin"));
  // The same tree declared one level shallower: a node at the last level has children.
  testing::ExpectInputError(
      [&] {
        Vocabulary::FromBytes(Resealed(bytes, [](std::string* b) { (*b)[12] = 2; }), "v.bin");
      },
      "v.bin: inconsistent vocabulary: node");
  const size_t idf_start =
      bytes.size() - 8 - 4 * static_cast<size_t>(Vocabulary::FromBytes(bytes, "v").NumWords());
  testing::ExpectInputError(
      [&] {
        Vocabulary::FromBytes(
            Resealed(bytes, [&](std::string* b) { PutFloat(b, idf_start, 3e38f); }), "v.bin");
      },
      "inconsistent vocabulary: weight of word 0");
  testing::ExpectInputError(
      [&] {
        Vocabulary::FromBytes(Resealed(bytes,
                                       [&](std::string* b) {
                                         for (size_t at = idf_start; at + 8 < b->size() + 8;
                                              at += 4)
                                           PutFloat(b, at, 0.0f);
                                       }),
                              "v.bin");
      },
      "every word weighs 0");
  // A file longer than its header says is refused before it is read whole.
  const std::string path = ::testing::TempDir() + "dynorb_vocab_oversized.bin";
  { std::ofstream(path, std::ios::binary) << bytes << std::string(1000, '\0'); }
  testing::ExpectInputError([&] { Vocabulary::Load(path); }, "its size does not match its header");
  std::remove(path.c_str());
  // One image: ln(1 / 1) = 0 for every word.
  testing::ExpectInputError(
      [&] {
        Vocabulary::Train({images[0], cv::Mat()}, o);
      },
      "descriptors from at least 2 images, got 1");
}

// The checked-in file (written by an earlier `dynorb vocab`) is exactly what ToBytes writes, and
// its fields sealed again give the file back: magic first, checksum last.
TEST(BuiltInVocabulary, FileBytesAreToBytesAndSealedFields) {
  std::ifstream in(std::string(DYNORB_SOURCE_DIR) + "/config/orb_vocabulary.dynvoc",
                   std::ios::binary);
  const std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(file.size(), 16u);
  EXPECT_EQ(BuiltInVocabulary()->ToBytes(), file);
  EXPECT_EQ(SealVocabularyBytes(file.substr(8, file.size() - 16)), file);
  EXPECT_NE(SealVocabularyBytes(file.substr(8, file.size() - 17) + "x"), file);
}

TEST(BuiltInVocabulary, IsTheCheckoutsFileAndSeparatesPlaces) {
  const std::shared_ptr<const Vocabulary> v = BuiltInVocabulary();
  EXPECT_EQ(
      v->ToBytes(),
      Vocabulary::Load(std::string(DYNORB_SOURCE_DIR) + "/config/orb_vocabulary.dynvoc").ToBytes());
  EXPECT_EQ(v->branching(), 10);
  EXPECT_EQ(v->levels(), 4);
  EXPECT_GT(v->NumWords(), 5000);
  EXPECT_EQ(BuiltInVocabulary().get(), v.get());  // parsed once
  // Random descriptors spread over many words.
  const cv::Mat random = RandomPrototypes(1000, 21);
  std::set<uint32_t> words;
  for (int r = 0; r < random.rows; ++r) words.insert(v->Word(random.ptr<uint8_t>(r)));
  EXPECT_GT(words.size(), 300u);
}

}  // namespace
}  // namespace dynorb
