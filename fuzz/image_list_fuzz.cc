// Fuzz target: a sequence's rgb.txt / depth.txt lists and associations.txt.
#include <cstddef>
#include <cstdint>

#include "dynorb/io/association.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dynorb::fuzz::WriteInput(data, size, ".txt");
  dynorb::fuzz::AllowInputError([&] {
    const auto list = dynorb::ReadImageList(path);
    dynorb::AssociateImageLists(list, list);
  });
  dynorb::fuzz::AllowInputError([&] { dynorb::ReadAssociationsFile(path); });
  return 0;
}
