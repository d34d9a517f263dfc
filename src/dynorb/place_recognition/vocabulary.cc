#include "dynorb/place_recognition/vocabulary.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "dynorb/core/error.h"
#include "dynorb/features/brief_pattern.h"
#include "dynorb/features/orb_matcher.h"
#include "dynorb/io/atomic_file.h"

namespace dynorb {
namespace {

constexpr char kMagic[8] = {'D', 'Y', 'N', 'V', 'O', 'C', '0', '1'};
constexpr float kMaxIdf = 64.0f;  // A word weight above this is no ln(images / images with it).
constexpr int kBits = kBriefBytes * 8;

void CheckDescriptors(const cv::Mat& d, const std::string& what) {
  if (!d.empty() && (d.type() != CV_8UC1 || d.cols != kBriefBytes)) {
    throw InputError(what + ": descriptors must be CV_8UC1 with " + std::to_string(kBriefBytes) +
                     " columns");
  }
}

uint64_t Fnv1a(const char* data, size_t size) {
  uint64_t h = 1469598103934665603ULL;
  for (size_t i = 0; i < size; ++i) {
    h ^= static_cast<uint8_t>(data[i]);
    h *= 1099511628211ULL;
  }
  return h;
}

// Little-endian fixed-width fields, independent of the host's byte order.
void PutU32(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void PutU64(std::string* out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

class Reader {
 public:
  Reader(const std::string& bytes, size_t end, const std::string& name)
      : bytes_(bytes), end_(end), name_(name) {}
  uint64_t Get(int width) {
    Need(width);
    uint64_t v = 0;
    for (int i = 0; i < width; ++i)
      v |= static_cast<uint64_t>(static_cast<uint8_t>(bytes_[pos_ + i])) << (8 * i);
    pos_ += width;
    return v;
  }
  void Copy(uint8_t* out, size_t n) {
    Need(n);
    std::memcpy(out, bytes_.data() + pos_, n);
    pos_ += n;
  }
  size_t position() const { return pos_; }

 private:
  void Need(size_t n) const {
    if (pos_ + n > end_) throw InputError(name_ + ": vocabulary file is truncated");
  }
  const std::string& bytes_;
  size_t end_;
  const std::string& name_;
  size_t pos_ = sizeof(kMagic);
};

// Bits of the given rows as 0/1 floats, one row per descriptor (bit j of byte b at column 8b + j).
cv::Mat BitsAsFloats(const cv::Mat& all, const std::vector<int>& rows) {
  cv::Mat out(static_cast<int>(rows.size()), kBits, CV_32F);
  for (size_t r = 0; r < rows.size(); ++r) {
    const uint8_t* d = all.ptr<uint8_t>(rows[r]);
    float* f = out.ptr<float>(static_cast<int>(r));
    for (int b = 0; b < kBriefBytes; ++b) {
      for (int j = 0; j < 8; ++j) f[8 * b + j] = static_cast<float>((d[b] >> j) & 1);
    }
  }
  return out;
}

using Centre = std::array<uint8_t, kBriefBytes>;

// Bit majority of each cluster's members (ties: bit clear).
std::vector<Centre> MajorityCentres(const cv::Mat& all, const std::vector<int>& rows,
                                    const cv::Mat& labels, int k) {
  std::vector<std::array<int, kBits>> ones(k);
  std::vector<int> count(k, 0);
  for (auto& o : ones) o.fill(0);
  for (size_t r = 0; r < rows.size(); ++r) {
    const int c = labels.at<int>(static_cast<int>(r));
    ++count[c];
    const uint8_t* d = all.ptr<uint8_t>(rows[r]);
    for (int b = 0; b < kBriefBytes; ++b) {
      for (int j = 0; j < 8; ++j) ones[c][8 * b + j] += (d[b] >> j) & 1;
    }
  }
  std::vector<Centre> centres;
  for (int c = 0; c < k; ++c) {
    if (count[c] == 0) continue;
    Centre centre{};
    for (int bit = 0; bit < kBits; ++bit) {
      if (2 * ones[c][bit] > count[c]) centre[bit / 8] |= static_cast<uint8_t>(1u << (bit % 8));
    }
    centres.push_back(centre);
  }
  return centres;
}

int Nearest(const uint8_t* d, const std::vector<Centre>& centres) {
  int best = 0, best_distance = kBits + 1;
  for (size_t c = 0; c < centres.size(); ++c) {
    const int distance = HammingDistance256(d, centres[c].data());
    if (distance < best_distance) {
      best_distance = distance;
      best = static_cast<int>(c);
    }
  }
  return best;
}

}  // namespace

double BowScore(const BowVector& a, const BowVector& b) {
  double score = 0.0;
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (a[i].word < b[j].word) {
      ++i;
    } else if (b[j].word < a[i].word) {
      ++j;
    } else {
      score += std::min(a[i].weight, b[j].weight);  // = (|a|+|b|-|a-b|)/2 for positive weights
      ++i;
      ++j;
    }
  }
  return std::min(1.0, score);
}

void VocabularyOptions::Validate() const {
  if (branching < 2 || branching > 64) throw InputError("vocabulary branching must be in 2..64");
  if (levels < 1 || levels > 8) throw InputError("vocabulary levels must be in 1..8");
  if (std::pow(static_cast<double>(branching), levels) > 1e7) {
    throw InputError("vocabulary branching^levels must be at most 1e7 words");
  }
  if (kmeans_iterations < 1) throw InputError("vocabulary kmeans_iterations must be >= 1");
  if (max_cluster_descriptors < branching)
    throw InputError("vocabulary max_cluster_descriptors must be >= branching");
}

Vocabulary Vocabulary::Train(const std::vector<cv::Mat>& descriptors_per_image,
                             const VocabularyOptions& options) {
  options.Validate();
  for (const cv::Mat& d : descriptors_per_image) CheckDescriptors(d, "vocabulary training");
  int total = 0;
  for (const cv::Mat& d : descriptors_per_image) total += d.rows;
  const int stride =
      std::max(1, (total + options.max_cluster_descriptors - 1) / options.max_cluster_descriptors);
  cv::Mat all;
  int row = 0;
  for (const cv::Mat& d : descriptors_per_image) {
    for (int r = 0; r < d.rows; ++r, ++row) {
      if (row % stride == 0) all.push_back(d.row(r));
    }
  }
  if (all.rows < options.branching) {
    throw InputError("vocabulary training needs at least " + std::to_string(options.branching) +
                     " descriptors, got " + std::to_string(all.rows));
  }

  Vocabulary v;
  v.branching_ = options.branching;
  v.levels_ = options.levels;
  std::vector<Centre> centres(1, Centre{});
  v.nodes_.emplace_back();
  struct Pending {
    uint32_t node;
    int depth;
    std::vector<int> rows;
  };
  std::deque<Pending> queue;
  std::vector<int> every(all.rows);
  for (int r = 0; r < all.rows; ++r) every[r] = r;
  queue.push_back({0, 0, std::move(every)});
  int num_words = 0;
  // Breadth first, so that each node's children are contiguous and words are numbered level by
  // level.
  while (!queue.empty()) {
    Pending p = std::move(queue.front());
    queue.pop_front();
    std::vector<Centre> child_centres;
    if (p.depth < options.levels && p.rows.size() > 1) {
      if (static_cast<int>(p.rows.size()) <= options.branching) {
        for (int r : p.rows) {  // each distinct descriptor its own child
          Centre c;
          std::memcpy(c.data(), all.ptr<uint8_t>(r), kBriefBytes);
          if (std::find(child_centres.begin(), child_centres.end(), c) == child_centres.end()) {
            child_centres.push_back(c);
          }
        }
      } else {
        cv::Mat labels, float_centres;
        cv::theRNG() = cv::RNG(options.seed * 0x9E3779B97F4A7C15ULL + p.node + 1);
        cv::kmeans(BitsAsFloats(all, p.rows), options.branching, labels,
                   cv::TermCriteria(cv::TermCriteria::COUNT, options.kmeans_iterations, 0.0), 1,
                   cv::KMEANS_PP_CENTERS, float_centres);
        child_centres = MajorityCentres(all, p.rows, labels, options.branching);
      }
    }
    if (child_centres.size() <= 1) {  // a leaf: the depth limit, one member, or one distinct centre
      v.nodes_[p.node].word = num_words++;
      continue;
    }
    std::vector<std::vector<int>> members(child_centres.size());
    for (int r : p.rows) members[Nearest(all.ptr<uint8_t>(r), child_centres)].push_back(r);
    v.nodes_[p.node].first_child = static_cast<uint32_t>(v.nodes_.size());
    for (size_t c = 0; c < child_centres.size(); ++c) {
      if (members[c].empty()) continue;  // a majority centre nobody is nearest to
      const uint32_t child = static_cast<uint32_t>(v.nodes_.size());
      v.nodes_.emplace_back();
      centres.push_back(child_centres[c]);
      ++v.nodes_[p.node].num_children;
      queue.push_back({child, p.depth + 1, std::move(members[c])});
    }
  }
  v.centres_ = cv::Mat(static_cast<int>(centres.size()), kBriefBytes, CV_8UC1);
  for (size_t n = 0; n < centres.size(); ++n) {
    std::memcpy(v.centres_.ptr<uint8_t>(static_cast<int>(n)), centres[n].data(), kBriefBytes);
  }

  // idf over the training images (one image: every weight would be ln 1 = 0, nothing to match).
  const auto with_descriptors =
      std::count_if(descriptors_per_image.begin(), descriptors_per_image.end(),
                    [](const cv::Mat& d) { return !d.empty(); });
  if (with_descriptors < 2) {
    throw InputError("vocabulary training needs descriptors from at least 2 images, got " +
                     std::to_string(with_descriptors) + ": every word would weigh 0");
  }
  v.idf_.assign(num_words, 0.0f);
  std::vector<int> images_with_word(num_words, 0);
  int num_images = 0;
  for (const cv::Mat& d : descriptors_per_image) {
    if (d.empty()) continue;
    ++num_images;
    std::vector<uint32_t> words;
    for (int r = 0; r < d.rows; ++r) words.push_back(v.Word(d.ptr<uint8_t>(r)));
    std::sort(words.begin(), words.end());
    words.erase(std::unique(words.begin(), words.end()), words.end());
    for (uint32_t w : words) ++images_with_word[w];
  }
  for (int w = 0; w < num_words; ++w) {
    v.idf_[w] = static_cast<float>(
        std::log(static_cast<double>(num_images) / std::max(1, images_with_word[w])));
  }
  if (std::all_of(v.idf_.begin(), v.idf_.end(), [](float f) { return f == 0.0f; })) {
    throw InputError("every one of the " + std::to_string(num_words) +
                     " vocabulary words is in every training image: such a vocabulary cannot "
                     "tell places apart (train on more varied images, or with more words: "
                     "branching / levels)");
  }
  return v;
}

uint32_t Vocabulary::Word(const uint8_t* descriptor) const {
  uint32_t node = 0;
  while (nodes_[node].num_children > 0) {
    const Node& n = nodes_[node];
    uint32_t best = n.first_child;
    int best_distance = kBits + 1;
    for (uint32_t c = n.first_child; c < n.first_child + n.num_children; ++c) {
      const int distance =
          HammingDistance256(descriptor, centres_.ptr<uint8_t>(static_cast<int>(c)));
      if (distance < best_distance) {
        best_distance = distance;
        best = c;
      }
    }
    node = best;
  }
  return static_cast<uint32_t>(nodes_[node].word);
}

BowVector Vocabulary::Transform(const cv::Mat& descriptors) const {
  CheckDescriptors(descriptors, "bag of words");
  BowVector bow;
  if (empty() || descriptors.empty()) return bow;
  std::vector<uint32_t> words(descriptors.rows);
  for (int r = 0; r < descriptors.rows; ++r) words[r] = Word(descriptors.ptr<uint8_t>(r));
  std::sort(words.begin(), words.end());
  double total = 0.0;
  for (uint32_t w : words) {
    if (!bow.empty() && bow.back().word == w) {
      bow.back().weight += idf_[w];
    } else {
      bow.push_back({w, idf_[w]});
    }
    total += idf_[w];
  }
  if (total <= 0.0) return {};  // only words that every training image has: no information
  BowVector out;
  for (const BowEntry& e : bow) {
    if (e.weight > 0.0f) out.push_back({e.word, static_cast<float>(e.weight / total)});
  }
  return out;
}

std::string SealVocabularyBytes(const std::string& fields) {
  std::string out(kMagic, sizeof(kMagic));
  out += fields;
  PutU64(&out, Fnv1a(out.data(), out.size()));
  return out;
}

std::string Vocabulary::ToBytes() const {
  std::string out;
  PutU32(&out, static_cast<uint32_t>(branching_));
  PutU32(&out, static_cast<uint32_t>(levels_));
  PutU32(&out, static_cast<uint32_t>(nodes_.size()));
  PutU32(&out, static_cast<uint32_t>(idf_.size()));
  for (size_t n = 0; n < nodes_.size(); ++n) {
    PutU32(&out, nodes_[n].first_child);
    PutU32(&out, nodes_[n].num_children);
    PutU32(&out, static_cast<uint32_t>(nodes_[n].word));
    out.append(reinterpret_cast<const char*>(centres_.ptr<uint8_t>(static_cast<int>(n))),
               kBriefBytes);
  }
  for (float f : idf_) {
    uint32_t bits;
    std::memcpy(&bits, &f, 4);
    PutU32(&out, bits);
  }
  return SealVocabularyBytes(out);
}

Vocabulary Vocabulary::FromBytes(const std::string& bytes, const std::string& name) {
  if (bytes.size() < sizeof(kMagic) + 8 || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    throw InputError(name +
                     ": not a dynorb vocabulary (expected a file written by 'dynorb vocab')");
  }
  const size_t body = bytes.size() - 8;
  uint64_t stored = 0;
  for (int i = 0; i < 8; ++i)
    stored |= static_cast<uint64_t>(static_cast<uint8_t>(bytes[body + i])) << (8 * i);
  if (stored != Fnv1a(bytes.data(), body))
    throw InputError(name + ": vocabulary file is corrupt (checksum mismatch)");

  Reader in(bytes, body, name);
  Vocabulary v;
  v.branching_ = static_cast<int>(in.Get(4));
  v.levels_ = static_cast<int>(in.Get(4));
  const uint64_t num_nodes = in.Get(4), num_words = in.Get(4);
  const auto bad = [&](const std::string& what) {
    return InputError(name + ": inconsistent vocabulary: " + what);
  };
  if (v.branching_ < 2 || v.branching_ > 64 || v.levels_ < 1 || v.levels_ > 8)
    throw bad("branching or levels");
  if (num_nodes == 0 || num_words == 0 || num_words > num_nodes) throw bad("node or word count");
  if (body != sizeof(kMagic) + 16 + num_nodes * (12 + kBriefBytes) + num_words * 4)
    throw bad("file size");
  v.nodes_.resize(num_nodes);
  v.centres_ = cv::Mat(static_cast<int>(num_nodes), kBriefBytes, CV_8UC1);
  std::vector<int> word_seen(num_words, 0);
  // Every node but the root has one parent and lies at most `levels` below the root: a descent
  // takes at most `levels` steps (a hand-made chain of 1e5 nodes made every lookup walk it).
  std::vector<int> depth(num_nodes, -1);
  depth[0] = 0;
  for (uint64_t n = 0; n < num_nodes; ++n) {
    Node& node = v.nodes_[n];
    node.first_child = static_cast<uint32_t>(in.Get(4));
    node.num_children = static_cast<uint32_t>(in.Get(4));
    node.word = static_cast<int32_t>(static_cast<uint32_t>(in.Get(4)));
    in.Copy(v.centres_.ptr<uint8_t>(static_cast<int>(n)), kBriefBytes);
    if (node.num_children > 0) {
      // Children after their parent: every descent ends.
      if (node.word != -1 || node.num_children > static_cast<uint32_t>(v.branching_) ||
          node.first_child <= n ||
          static_cast<uint64_t>(node.first_child) + node.num_children > num_nodes || depth[n] < 0 ||
          depth[n] >= v.levels_) {
        throw bad("node " + std::to_string(n));
      }
      for (uint32_t c = node.first_child; c < node.first_child + node.num_children; ++c) {
        if (depth[c] >= 0) throw bad("node " + std::to_string(c) + " has two parents");
        depth[c] = depth[n] + 1;
      }
    } else {
      if (depth[n] < 0 || node.word < 0 || static_cast<uint64_t>(node.word) >= num_words ||
          word_seen[node.word]++) {
        throw bad("leaf " + std::to_string(n));
      }
    }
  }
  v.idf_.resize(num_words);
  for (uint64_t w = 0; w < num_words; ++w) {
    const uint32_t bits = static_cast<uint32_t>(in.Get(4));
    std::memcpy(&v.idf_[w], &bits, 4);
    // ln(images / images with the word) <= ln(2^32) ~ 22 for any training set.
    if (!std::isfinite(v.idf_[w]) || v.idf_[w] < 0.0f || v.idf_[w] > kMaxIdf)
      throw bad("weight of word " + std::to_string(w));
    if (!word_seen[w]) throw bad("word " + std::to_string(w) + " has no leaf");
  }
  if (std::all_of(v.idf_.begin(), v.idf_.end(), [](float f) { return f == 0.0f; }))
    throw bad("every word weighs 0 (trained on one image?): no image would have a bag of words");
  return v;
}

Vocabulary Vocabulary::Load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open vocabulary file");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(path + ": not a regular file (a vocabulary written by 'dynorb vocab')");
  // The size the header announces, before reading the rest (a 1 GB file of zeros was read whole).
  const uint64_t size = std::filesystem::file_size(path, ec);
  std::string header(sizeof(kMagic) + 16, '\0');
  in.read(header.data(), static_cast<std::streamsize>(header.size()));
  if (in && std::memcmp(header.data(), kMagic, sizeof(kMagic)) == 0) {
    uint64_t num_nodes = 0, num_words = 0;
    for (int i = 0; i < 4; ++i) {
      num_nodes |= static_cast<uint64_t>(static_cast<uint8_t>(header[16 + i])) << (8 * i);
      num_words |= static_cast<uint64_t>(static_cast<uint8_t>(header[20 + i])) << (8 * i);
    }
    if (ec || size != header.size() + num_nodes * (12 + kBriefBytes) + num_words * 4 + 8)
      throw InputError(path + ": vocabulary file is corrupt (its size does not match its header)");
  }
  in.seekg(0);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return FromBytes(bytes.str(), path);
}

void Vocabulary::Save(const std::string& path) const { WriteFileAtomically(path, ToBytes()); }

}  // namespace dynorb
