// Fuzz target: vocabulary files (Vocabulary::FromBytes: what `Vocabulary::Load` reads for the
// `vocabulary:` key of a config). A file's last 8 bytes are a checksum of the rest, which random
// bytes never match: the input is the file between the magic and the checksum, and the target adds
// both (SealVocabularyBytes), so that the fuzzer reaches the structural checks. A vocabulary that
// loads then sorts descriptors made of the input's bytes into words (every descent must end on a
// word).
#include <cstddef>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "dynorb/place_recognition/vocabulary.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes =
      dynorb::SealVocabularyBytes(std::string(reinterpret_cast<const char*>(data), size));
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
