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

// A command's output folder. The constructor creates it (with its missing parents) or throws
// InputError("cannot create <what> <path>"). Destroyed without Keep() (the command failed), it
// removes the folders it created if they are still empty, so a failed command leaves no empty
// output folder behind; a folder that existed before is never removed. Not thread-safe.
class OutputFolder {
 public:
  explicit OutputFolder(const std::string& path, const std::string& what = "output folder");
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  void Keep() { keep_ = true; }

 private:
  void RemoveCreated() const;  // Innermost first; stops at a folder that is no longer empty.

  std::vector<std::string> created_;  // Outermost first.
  bool keep_ = false;
};

// Writes `content` to `path` atomically.
void WriteFileAtomically(const std::string& path, const std::string& content);

}  // namespace dynorb
