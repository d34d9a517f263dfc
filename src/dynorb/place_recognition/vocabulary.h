// Vocabulary: a tree of binary ORB words (hierarchical k-majority clustering, as DBoW2 builds
// for ORB-SLAM2) that turns a frame's descriptors into a weighted bag of words, so that two
// frames of the same place can be recognised without matching their descriptors.
//
// Training clusters the descriptors with OpenCV's k-means on their bits as 0/1 floats (the squared
// Euclidean distance of two bit vectors is their Hamming distance; k-means++ seeding, one RNG seed
// per node, so a vocabulary is reproducible) and rounds each centre to the bit majority; every
// descriptor then goes to its nearest binary centre. Leaves at depth `levels` are the words, each
// weighted by its inverse document frequency over the training images (idf = ln(N / N_w)).
// Immutable after construction: Transform and Score are thread-safe.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace dynorb {

struct BowEntry {
  uint32_t word = 0;
  float weight = 0.0f;
};
// Sorted by word, weights (tf-idf) summing to 1; empty for a frame without descriptors.
using BowVector = std::vector<BowEntry>;

// Similarity of two bag-of-words vectors in [0, 1] (DBoW2's L1 score: 1 - |a - b|_1 / 2).
double BowScore(const BowVector& a, const BowVector& b);

struct VocabularyOptions {
  int branching = 10;  // k: children per node (2..64)
  int levels = 4;      // depth of the leaves (1..8); at most branching^levels words
  int kmeans_iterations = 10;
  uint64_t seed = 1;
  // At most this many descriptors are clustered (every k-th, k = ceil(total / max)): clustering
  // holds each as 256 floats (1 KB). The idf weights count every image's descriptors.
  int max_cluster_descriptors = 500000;

  // Throws InputError on out-of-range values.
  void Validate() const;
};

// The binary form's framing around its fields: the magic first, a checksum of everything before
// it last (what ToBytes writes and FromBytes checks). For tools that write the fields themselves
// (the fuzz target).
std::string SealVocabularyBytes(const std::string& fields);

class Vocabulary {
 public:
  Vocabulary() = default;

  // descriptors_per_image: CV_8UC1 × 32 columns each (one matrix per training image; the image
  // count gives the idf weights). Throws InputError on bad options or fewer descriptors than
  // `branching`.
  static Vocabulary Train(const std::vector<cv::Mat>& descriptors_per_image,
                          const VocabularyOptions& options);

  // The binary form (ToBytes) back; `name` is used in error messages. Throws InputError on a
  // truncated, corrupt (checksum) or inconsistent input.
  static Vocabulary FromBytes(const std::string& bytes, const std::string& name);
  std::string ToBytes() const;
  // Reads / writes a file in the binary form (Save writes through a temporary file).
  static Vocabulary Load(const std::string& path);
  void Save(const std::string& path) const;

  bool empty() const { return idf_.empty(); }
  int NumWords() const { return static_cast<int>(idf_.size()); }
  int branching() const { return branching_; }
  int levels() const { return levels_; }
  float idf(uint32_t word) const { return idf_[word]; }

  // The word (leaf) of one 32-byte descriptor: the nearest centre at each level.
  uint32_t Word(const uint8_t* descriptor) const;
  // tf-idf bag of words of a descriptor matrix (CV_8UC1 × 32; rows in any order).
  BowVector Transform(const cv::Mat& descriptors) const;

 private:
  struct Node {
    uint32_t first_child = 0;  // index of the first child in nodes_; children are contiguous
    uint32_t num_children = 0;
    int32_t word = -1;  // leaves only
  };

  int branching_ = 0;
  int levels_ = 0;
  std::vector<Node> nodes_;  // nodes_[0] is the root (no centre)
  cv::Mat centres_;          // one 32-byte row per node (row 0 unused)
  std::vector<float> idf_;   // per word
};

}  // namespace dynorb
