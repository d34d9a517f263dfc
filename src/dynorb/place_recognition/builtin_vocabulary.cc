#include "dynorb/place_recognition/builtin_vocabulary.h"

#include <string>

// DYNORB_VOCABULARY_FILE: absolute path of config/orb_vocabulary.dynvoc (CMakeLists.txt).
__asm__(
    ".pushsection .rodata\n"
    ".balign 16\n"
    "dynorb_builtin_vocabulary_begin:\n"
    ".incbin \"" DYNORB_VOCABULARY_FILE
    "\"\n"
    "dynorb_builtin_vocabulary_end:\n"
    ".popsection\n");
extern "C" const char dynorb_builtin_vocabulary_begin[];
extern "C" const char dynorb_builtin_vocabulary_end[];

namespace dynorb {

std::shared_ptr<const Vocabulary> BuiltInVocabulary() {
  static const std::shared_ptr<const Vocabulary> vocabulary =
      std::make_shared<const Vocabulary>(Vocabulary::FromBytes(
          std::string(dynorb_builtin_vocabulary_begin, dynorb_builtin_vocabulary_end),
          "built-in vocabulary"));
  return vocabulary;
}

}  // namespace dynorb
