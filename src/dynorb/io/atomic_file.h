// AtomicFile: write an output file so that it either appears complete or not at all.
// Data goes to a temporary file next to the target; Commit() renames it into place. If the
// object is destroyed without Commit() (an error was thrown), the temporary file is removed, so
// a failed run never leaves a half-written output behind. Not thread-safe.
#pragma once

#include <fstream>
#include <string>
#include <vector>

namespace dynorb {

class AtomicFile {
 public:
  // Throws InputError if the directory of `path` is not writable.
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() { return out_; }
  const std::string& temp_path() const { return temp_path_; }
  // Flushes, checks the stream and renames into place. Throws InputError on I/O failure.
  void Commit();

 private:
  std::string path_;
  std::string temp_path_;
  std::ofstream out_;
  bool committed_ = false;
};

// Throws InputError naming the first of `paths` that exists and is not a file (a directory,
// say), so that a command can refuse before it writes any of its outputs.
void CheckOutputTargets(const std::vector<std::string>& paths);

// Writes `content` to `path` atomically.
void WriteFileAtomically(const std::string& path, const std::string& content);

}  // namespace dynorb
