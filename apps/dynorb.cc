// dynorb: one CLI, one subcommand per job (see README.md). Thin: parsing and error reporting only.
#include <malloc.h>

#include <iostream>

#include <CLI/CLI.hpp>

#include "command_registry.h"
#include "dynorb/core/error.h"

namespace {

// Keep freed memory in the process. By default glibc hands blocks above 128 KB (images, pyramids,
// DNN blobs: allocated and freed every frame) back to the kernel and trims the heaps, so the next
// frame pays an munmap or madvise and a page fault per 4 KB page touched again; on the 2-core VM
// of session 37 that was 0.8 ms of plain mode's 6.7 ms per frame (docs/slam_core.md, "Speed").
// The cost: the resident size stays at its peak, which a SLAM run reaches early anyway.
void KeepFreedMemory() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // blocks up to 32 MB come from the heaps
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

}  // namespace

int main(int argc, char** argv) {
  KeepFreedMemory();
  CLI::App app{"dynorb: RGB-D SLAM that keeps moving people and objects out of the map"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "dynorb 0.1.0");
  dynorb::AddRegisteredCommands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const dynorb::InputError& e) {
    std::cerr << "dynorb: error: " << e.what() << std::endl;
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "dynorb: error: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
