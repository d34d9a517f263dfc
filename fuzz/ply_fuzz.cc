// Fuzz target: PLY point clouds (ReadPlyPointCloud: maps written by `dynorb run --save-map`).
#include <cstddef>
#include <cstdint>

#include "dynorb/io/point_cloud_io.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dynorb::fuzz::WriteInput(data, size, ".ply");
  dynorb::fuzz::AllowInputError([&] { dynorb::ReadPlyPointCloud(path); });
  return 0;
}
