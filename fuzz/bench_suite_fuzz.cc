// Fuzz target: benchmark suites (`dynorb bench --suite`).
#include <cstddef>
#include <cstdint>
#include <string>

#include "dynorb/core/error.h"
#include "dynorb/io/bench_suite.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    dynorb::ParseBenchSuite(std::string(reinterpret_cast<const char*>(data), size), "suite.yaml",
                            "/suites");
  } catch (const dynorb::InputError&) {
  }
  return 0;
}
