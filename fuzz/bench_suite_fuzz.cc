// Fuzz target: benchmark suites (`dynorb bench --suite`).
#include <cstddef>
#include <cstdint>
#include <string>

#include "dynorb/io/bench_suite.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  dynorb::fuzz::AllowInputError([&] { dynorb::ParseBenchSuite(text, "suite.yaml", "/suites"); });
  return 0;
}
