// Replays the files of corpus folders through a fuzz target's LLVMFuzzerTestOneInput, for builds
// without libFuzzer (gcc): `dynorb_fuzz_<name>_replay DIR...`, registered with CTest on
// fuzz/corpus/<name>/ (seed inputs and every crash found so far). An input that makes the target
// throw anything but InputError, or crash, fails the test.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int main(int argc, char** argv) {
  int replayed = 0;
  for (int a = 1; a < argc; ++a) {
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(argv[a])) {
      if (entry.is_regular_file()) files.push_back(entry.path());
    }
    if (files.empty()) {
      std::cerr << argv[a] << ": no corpus files\n";
      return 1;
    }
    for (const auto& file : files) {
      std::ifstream in(file, std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(in)),
                              std::istreambuf_iterator<char>());
      std::cout << "replay " << file.filename().string() << " (" << bytes.size() << " bytes)"
                << std::endl;
      LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
      ++replayed;
    }
  }
  std::cout << replayed << " inputs replayed\n";
  // The targets' scratch files (fuzz_input.h: <tmp>/dynorb_fuzz_<pid>...) are not left behind.
  const std::string prefix = "dynorb_fuzz_" + std::to_string(getpid());
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::temp_directory_path())) {
    const std::string name = entry.path().filename().string();
    // The pid followed by the suffix's '.' or '_' (not another process's longer pid).
    if (name.rfind(prefix, 0) == 0 && name.size() > prefix.size() &&
        (name[prefix.size()] == '.' || name[prefix.size()] == '_'))
      std::filesystem::remove_all(entry.path());
  }
  return replayed > 0 ? 0 : 1;
}
