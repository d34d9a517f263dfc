// Helpers for the fuzz targets (fuzz/README in docs/conventions.md, "Fuzzing"): the parsers
// read files, so each input is written to a per-process temporary file first.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "dynorb/core/error.h"

namespace dynorb {
namespace fuzz {

// <tmp>/dynorb_fuzz_<pid><suffix>: a scratch path of this process.
inline std::string TempPath(const std::string& suffix) {
  static const std::string base =
      (std::filesystem::temp_directory_path() / ("dynorb_fuzz_" + std::to_string(getpid())))
          .string();
  return base + suffix;
}

// Writes the bytes to `path` (replacing it).
inline void WriteFile(const std::string& path, const uint8_t* data, size_t size) {
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

// Writes the input to TempPath(suffix) (the same file on every call) and returns its path.
inline std::string WriteInput(const uint8_t* data, size_t size, const std::string& suffix) {
  const std::string path = TempPath(suffix);
  WriteFile(path, data, size);
  return path;
}

// Runs `parse`; an InputError (the parsers' one way to refuse input) is the expected outcome,
// anything else thrown reaches libFuzzer (or the replay) as a failure.
template <typename Parse>
void AllowInputError(Parse&& parse) {
  try {
    parse();
  } catch (const InputError&) {
  }
}

}  // namespace fuzz
}  // namespace dynorb
