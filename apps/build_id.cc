#include "build_id.h"

#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <vector>

namespace dynorb {
namespace {

std::string ComputeBuildId() {
  std::ifstream in("/proc/self/exe", std::ios::binary);
  if (!in) return kUnknownBuildId;
  // FNV-1a over 8-byte words (the debug binary is ~100 MB; bytewise took ~0.2 s per run).
  uint64_t hash = 1469598103934665603ull;  // FNV-1a 64 offset basis
  std::vector<uint64_t> buffer(1 << 13);
  while (in) {
    in.read(reinterpret_cast<char*>(buffer.data()), static_cast<std::streamsize>(buffer.size() * sizeof(uint64_t)));
    const std::streamsize got = in.gcount();
    const size_t words = static_cast<size_t>(got) / sizeof(uint64_t);
    for (size_t i = 0; i < words; ++i) {
      hash ^= buffer[i];
      hash *= 1099511628211ull;  // FNV prime
    }
    const unsigned char* tail = reinterpret_cast<const unsigned char*>(buffer.data()) + words * sizeof(uint64_t);
    for (size_t i = 0; i < static_cast<size_t>(got) % sizeof(uint64_t); ++i) {
      hash ^= tail[i];
      hash *= 1099511628211ull;
    }
  }
  char text[32];
  std::snprintf(text, sizeof(text), "fnv1a64:%016" PRIx64, hash);
  return text;
}

}  // namespace

const std::string& BuildId() {
  static const std::string id = ComputeBuildId();
  return id;
}

}  // namespace dynorb
