#include "build_id.h"

#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <vector>

namespace dynorb {
namespace {

std::string ComputeBuildId() {
  std::ifstream in("/proc/self/exe", std::ios::binary);
  if (!in) return "unknown";
  uint64_t hash = 1469598103934665603ull;  // FNV-1a 64 offset basis
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const std::streamsize got = in.gcount();
    for (std::streamsize i = 0; i < got; ++i) {
      hash ^= static_cast<unsigned char>(buffer[i]);
      hash *= 1099511628211ull;  // FNV prime
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
