// Fuzz target: TUM trajectory files (`dynorb eval --gt/--est`): ReadTumTrajectory and
// ReadTumGroundTruth. Bad input must be an InputError, nothing else.
#include <cstddef>
#include <cstdint>

#include "dynorb/io/trajectory_io.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dynorb::fuzz::WriteInput(data, size, ".txt");
  dynorb::fuzz::AllowInputError([&] { dynorb::ReadTumTrajectory(path); });
  dynorb::fuzz::AllowInputError([&] { dynorb::ReadTumGroundTruth(path); });
  return 0;
}
