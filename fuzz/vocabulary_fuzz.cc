// Fuzz target: vocabulary files (Vocabulary::FromBytes: what `Vocabulary::Load` reads for the
// `vocabulary:` key of a config). A file's last 8 bytes are a checksum of the rest, which random
// bytes never match: the input is the file between the magic and the checksum, and the target adds
// both, so that the fuzzer reaches the structural checks. A vocabulary that loads then sorts
// descriptors made of the input's bytes into words (every descent must end on a word).
#include <cstddef>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "dynorb/place_recognition/vocabulary.h"
#include "fuzz_input.h"

namespace {

// The file format's checksum: 64-bit FNV-1a of everything before it, stored little-endian.
void AppendChecksum(std::string* bytes) {
  uint64_t h = 1469598103934665603ULL;
  for (const char c : *bytes) {
    h ^= static_cast<uint8_t>(c);
    h *= 1099511628211ULL;
  }
  for (int i = 0; i < 8; ++i) bytes->push_back(static_cast<char>((h >> (8 * i)) & 0xff));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string bytes = "DYNVOC01";
  bytes.append(reinterpret_cast<const char*>(data), size);
  AppendChecksum(&bytes);
  dynorb::fuzz::AllowInputError([&] {
    const dynorb::Vocabulary vocabulary = dynorb::Vocabulary::FromBytes(bytes, "fuzz.voc");
    cv::Mat descriptors(4, 32, CV_8UC1);
    for (int i = 0; i < descriptors.rows * descriptors.cols; ++i)
      descriptors.data[i] = size > 0 ? data[i % size] : 0;
    for (const dynorb::BowEntry& e : vocabulary.Transform(descriptors)) {
      if (static_cast<int>(e.word) >= vocabulary.NumWords()) __builtin_trap();
    }
  });
  return 0;
}
