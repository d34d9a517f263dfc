// Helpers for the fuzz targets (fuzz/README in docs/conventions.md, "Fuzzing"): the parsers
// read files, so each input is written to a per-process temporary file first.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace dynorb {
namespace fuzz {

// Writes the input to <tmp>/dynorb_fuzz_<pid><suffix> (the same file on every call) and returns
// its path.
inline std::string WriteInput(const uint8_t* data, size_t size, const std::string& suffix) {
  static const std::string base =
      (std::filesystem::temp_directory_path() / ("dynorb_fuzz_" + std::to_string(getpid())))
          .string();
  const std::string path = base + suffix;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace fuzz
}  // namespace dynorb
