#include "preload_budget.h"

#include <unistd.h>

#include <cstdio>

#include "dynorb/core/error.h"

namespace dynorb {

double PreloadBytes(size_t frames, int width, int height, bool with_masks) {
  const double pixels = static_cast<double>(width) * static_cast<double>(height);
  return static_cast<double>(frames) * pixels * (3.0 + 4.0 + (with_masks ? 2.0 : 0.0));
}

double PhysicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page_size <= 0) return 0.0;
  return static_cast<double>(pages) * static_cast<double>(page_size);
}

void CheckPreloadFits(size_t frames, double bytes, double machine_bytes) {
  if (machine_bytes <= 0.0 || bytes <= 0.5 * machine_bytes) return;
  char text[256];
  std::snprintf(text, sizeof(text),
                "--preload needs about %.1f GB for %zu frames, more than half of this machine's memory (%.1f GB); "
                "use --frames A:B or leave out --preload",
                bytes / 1e9, frames, machine_bytes / 1e9);
  throw InputError(text);
}

}  // namespace dynorb
