#include "dynorb/io/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>

#include "dynorb/core/error.h"

namespace dynorb {

void CheckOutputTargets(const std::vector<std::string>& paths) {
  namespace fs = std::filesystem;
  for (const std::string& path : paths) {
    std::error_code ec;
    const fs::file_status status = fs::symlink_status(path, ec);
    if (!fs::exists(status) || fs::is_regular_file(status) || fs::is_symlink(status)) continue;
    throw InputError("cannot write " + path + ": it exists and is not a file");
  }
}

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  namespace fs = std::filesystem;
  CheckOutputTargets({path_});
  const fs::path target(path_);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError("output directory does not exist: " + dir.string());
  // Process id and a counter: two threads writing one target never share a temporary file.
  static std::atomic<unsigned long long> counter{0};
  temp_path_ = (dir / ("." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) +
                       "-" + std::to_string(counter++)))
                   .string();
  out_.open(temp_path_, std::ios::binary | std::ios::trunc);
  if (!out_) throw InputError("cannot write to " + path_ + " (is the directory writable?)");
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::remove(temp_path_.c_str());
  }
}

void AtomicFile::Commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok) throw InputError("failed writing " + path_);
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    throw InputError("cannot move " + temp_path_ + " to " + path_);
  }
  committed_ = true;
}

OutputFolder::OutputFolder(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  // The missing folders on the way, outermost first (stops at the first one that exists).
  fs::path normal = fs::path(path).lexically_normal();
  if (normal.has_parent_path() && normal.filename().empty())
    normal = normal.parent_path();  // "out/"
  for (fs::path p = normal; !p.empty() && !fs::exists(fs::symlink_status(p, ec));
       p = p.parent_path()) {
    created_.insert(created_.begin(), p.string());
    if (p == p.parent_path()) break;
  }
  fs::create_directories(path, ec);
  if (!fs::is_directory(path, ec)) {
    RemoveCreated();  // A parent made on the way.
    throw InputError("cannot create " + what + " " + path);
  }
}

OutputFolder::~OutputFolder() {
  if (!keep_) RemoveCreated();
}

void OutputFolder::RemoveCreated() const {
  namespace fs = std::filesystem;
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) {
    std::error_code ec;
    if (!fs::is_directory(fs::symlink_status(*it, ec)) || !fs::is_empty(*it, ec) || ec) break;
    fs::remove(*it, ec);
  }
}

void WriteFileAtomically(const std::string& path, const std::string& content) {
  AtomicFile file(path);
  file.stream() << content;
  file.Commit();
}

}  // namespace dynorb
