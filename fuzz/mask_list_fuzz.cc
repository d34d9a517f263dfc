// Fuzz target: PNG mask lists of the semantic mode (`semantic: {source: masks, list: F}`), parsed
// by FileMaskProvider (the listed PNGs are not read).
#include <cstddef>
#include <cstdint>

#include "dynorb/dynamic/mask_file.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dynorb::fuzz::WriteInput(data, size, ".txt");
  dynorb::fuzz::AllowInputError([&] {
    dynorb::FileMaskProvider(path, dynorb::MaskFileKind::kMasks, dynorb::DepthRefineOptions());
  });
  return 0;
}
