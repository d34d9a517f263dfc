#include "dynorb/synth/sequence_writer.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "dynorb/core/error.h"
#include "dynorb/io/atomic_file.h"
#include "dynorb/io/config.h"
#include "dynorb/io/trajectory_io.h"
#include "dynorb/synth/png_writer.h"

namespace dynorb::synth {
namespace fs = std::filesystem;
namespace {

void WritePng(const std::string& path, const cv::Mat& image) {
  WriteFileAtomically(path, EncodePng(image));
}

}  // namespace

namespace {

constexpr char kStagingPrefix[] = ".partial-";

// The process id of a staging folder's name (".partial-<pid>"), or 0 when it is no such name.
long StagingPid(const fs::path& entry) {
  const std::string name = entry.filename().string();
  if (name.rfind(kStagingPrefix, 0) != 0) return 0;
  const std::string digits = name.substr(sizeof(kStagingPrefix) - 1);
  if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) return 0;
  return std::strtol(digits.c_str(), nullptr, 10);
}

}  // namespace

void SequenceWriter::CheckTarget(const std::string& dir, bool force) {
  std::error_code ec;
  if (dir.empty()) throw InputError("no output directory given");
  if (!fs::exists(dir, ec)) return;
  if (!fs::is_directory(dir, ec))
    throw InputError("output path exists and is not a directory: " + dir);
  if (force) return;
  // Staging folders of generations (interrupted ones are removed by the writer) do not count.
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (StagingPid(entry.path()) == 0)
      throw InputError("output directory is not empty: " + dir + " (use --force to overwrite)");
  }
}

SequenceWriter::SequenceWriter(std::string dir, bool force) : final_dir_(std::move(dir)) {
  CheckTarget(final_dir_, force);
  folder_.emplace(final_dir_, "output directory");  // Removed again if the generation fails.
  std::error_code ec;
  // Staging folders of generations that were killed (their process is gone).
  for (const auto& entry : fs::directory_iterator(final_dir_, ec)) {
    const long pid = StagingPid(entry.path());
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) {
      std::error_code ignored;
      fs::remove_all(entry.path(), ignored);
    }
  }
  // The staging folder inside the output folder: Commit() renames within one folder (no other
  // file system, symbolic links and read-only parents alike).
  dir_ = (fs::path(final_dir_) / (kStagingPrefix + std::to_string(::getpid()))).string();
  fs::remove_all(dir_, ec);
  for (const char* sub : {"rgb", "depth", "masks"}) {
    fs::create_directories(fs::path(dir_) / sub, ec);
    if (ec) {
      const std::string reason = ec.message();
      fs::remove_all(dir_, ec);
      throw InputError("cannot create output directory " + final_dir_ + " (" + reason + ")");
    }
  }
  // Fail early (before any rendering) if the directory is not writable.
  try {
    WriteFileAtomically((fs::path(dir_) / ".write_test").string(), "");
  } catch (const InputError&) {
    fs::remove_all(dir_, ec);
    throw;
  }
  fs::remove(fs::path(dir_) / ".write_test", ec);
}

SequenceWriter::~SequenceWriter() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(dir_, ec);  // A failed generation leaves nothing (and no folder it made).
}

void SequenceWriter::Commit() {
  // Each entry renamed into place; with --force an earlier sequence's entry of the same name is
  // replaced, anything else in the folder stays.
  for (const auto& entry : fs::directory_iterator(dir_)) {
    const fs::path to = fs::path(final_dir_) / entry.path().filename();
    std::error_code ec;
    fs::remove_all(to, ec);
    fs::rename(entry.path(), to, ec);
    if (ec) {
      throw InputError("cannot move " + entry.path().string() + " to " + to.string() + ": " +
                       ec.message());
    }
  }
  committed_ = true;
  folder_->Keep();
  std::error_code ec;
  fs::remove(dir_, ec);
}

std::string SequenceWriter::Stamp(double timestamp_s) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6f", timestamp_s);
  return buf;
}

void SequenceWriter::WriteFrame(double rgb_ts, double depth_ts, const cv::Mat& rgb,
                                const cv::Mat& depth_u16, const cv::Mat& mask) const {
  const fs::path root(dir_);
  WritePng((root / "rgb" / (Stamp(rgb_ts) + ".png")).string(), rgb);
  WritePng((root / "depth" / (Stamp(depth_ts) + ".png")).string(), depth_u16);
  WritePng((root / "masks" / (Stamp(rgb_ts) + ".png")).string(), mask);
}

void SequenceWriter::WriteIndex(const std::vector<double>& rgb_ts,
                                const std::vector<double>& depth_ts,
                                const Trajectory& groundtruth) const {
  std::ostringstream rgb, depth, masks, assoc;
  rgb << "# color images\n# file: 'dynorb synth'\n# timestamp filename\n";
  depth << "# depth maps\n# file: 'dynorb synth'\n# timestamp filename\n";
  masks << "# moving-object masks (pixel = object id, 0 = static)\n# file: 'dynorb synth'\n# "
           "timestamp filename\n";
  for (size_t i = 0; i < rgb_ts.size(); ++i) {
    const std::string r = Stamp(rgb_ts[i]), d = Stamp(depth_ts[i]);
    rgb << r << " rgb/" << r << ".png\n";
    depth << d << " depth/" << d << ".png\n";
    masks << r << " masks/" << r << ".png\n";
    assoc << r << " rgb/" << r << ".png " << d << " depth/" << d << ".png\n";
  }
  WriteText("rgb.txt", rgb.str());
  WriteText("depth.txt", depth.str());
  WriteText("masks.txt", masks.str());
  WriteText("associations.txt", assoc.str());
  WriteTumTrajectory((fs::path(dir_) / "groundtruth.txt").string(), groundtruth);
}

void SequenceWriter::WriteText(const std::string& name, const std::string& content) const {
  WriteFileAtomically((fs::path(dir_) / name).string(), content);
}

std::string SequenceWriter::CameraYaml(const PinholeCamera& c, double fps, double depth_factor) {
  auto num = [](double v) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.10g", v);
    std::string text = buf;
    if (text.find_first_of(".e") == std::string::npos) text += ".0";
    return text;
  };
  std::ostringstream s;
  s << "%YAML:1.0\n"
    << "# Camera of a dynorb synthetic sequence (TUM fr3 intrinsics, no distortion).\n"
    << "Camera.fx: " << num(c.fx) << "\nCamera.fy: " << num(c.fy) << "\nCamera.cx: " << num(c.cx)
    << "\nCamera.cy: " << num(c.cy) << "\nCamera.k1: " << num(c.k1) << "\nCamera.k2: " << num(c.k2)
    << "\nCamera.p1: " << num(c.p1) << "\nCamera.p2: " << num(c.p2) << "\nCamera.k3: " << num(c.k3)
    << "\nCamera.width: " << c.width << "\nCamera.height: " << c.height << "\nCamera.fps: "
    << num(fps)
    // bf and ThDepth: the code defaults (ORB-SLAM2's bf; ThDepth 50, docs/slam_core.md).
    << "\nCamera.bf: " << num(CameraConfig().bf)
    << "\nCamera.RGB: 1\nThDepth: " << num(CameraConfig().th_depth)
    << "\nDepthMapFactor: " << num(depth_factor)
    << "\nORBextractor.nFeatures: 1000\nORBextractor.scaleFactor: 1.2\nORBextractor.nLevels: 8"
    << "\nORBextractor.iniThFAST: 20\nORBextractor.minThFAST: 7\n";
  return s.str();
}

}  // namespace dynorb::synth
