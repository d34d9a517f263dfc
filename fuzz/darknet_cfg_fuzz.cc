// Fuzz target: darknet .cfg files of the detector models (`--models DIR`): the parser and the
// weight-size check that compares a .cfg with its .weights.
#include <cstddef>
#include <cstdint>

#include "dynorb/dynamic/darknet_model.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dynorb::fuzz::WriteInput(data, size, ".cfg");
  dynorb::fuzz::AllowInputError([&] {
    dynorb::ReadDarknetCfg(path);
    dynorb::DarknetExpectedWeightBytes(path, 20);
  });
  return 0;
}
