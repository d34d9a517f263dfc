// The ORB vocabulary built into dynorb: config/orb_vocabulary.dynvoc, embedded by the assembler
// (.incbin) at build time, trained with `dynorb vocab` on the real photographs of Debian's
// opencv-doc package (docs/place_recognition.md). 10 × 10 × 10 × 10 tree, ~10^4 words.
#pragma once

#include <memory>

#include "dynorb/place_recognition/vocabulary.h"

namespace dynorb {

// Parsed on first use (thread-safe), then shared.
std::shared_ptr<const Vocabulary> BuiltInVocabulary();

}  // namespace dynorb
