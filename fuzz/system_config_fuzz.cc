// Fuzz target: camera / system configuration files (`dynorb run --config`, ORB-SLAM2 keys, OpenCV
// FileStorage or plain YAML).
#include <cstddef>
#include <cstdint>

#include "dynorb/io/config.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dynorb::fuzz::WriteInput(data, size, ".yaml");
  dynorb::fuzz::AllowInputError([&] { dynorb::LoadSystemConfig(path); });
  return 0;
}
