// SequenceWriter: writes a synthetic sequence in the TUM RGB-D layout:
//   rgb/<ts>.png (8-bit BGR->RGB PNG), depth/<ts>.png (16-bit, factor 5000, 0 = none),
//   masks/<rgb ts>.png (8-bit moving-object id, 0 = static), rgb.txt, depth.txt, masks.txt,
//   associations.txt, groundtruth.txt (world_from_cam at the rgb timestamps), objects.txt,
//   camera.yaml (ORB-SLAM2 keys), scene.yaml (all generation parameters).
// Every file is written atomically (io/atomic_file.h), the whole sequence into a staging folder
// that Commit() moves into place. WriteFrame may be called concurrently
// for different frames; the rest is single-threaded.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/trajectory.h"
#include "dynorb/io/atomic_file.h"

namespace dynorb::synth {

class SequenceWriter {
 public:
  // Creates `dir` if needed and writes into a hidden staging folder inside it (.partial-<pid>,
  // with rgb/, depth/, masks/; those of killed generations are removed). Throws InputError if it
  // cannot be created or written, or if `dir` is not empty and `force` is false.
  SequenceWriter(std::string dir, bool force);
  // Without Commit() (generation failed) the staging folder is removed: no half-written sequence.
  ~SequenceWriter();
  SequenceWriter(const SequenceWriter&) = delete;
  SequenceWriter& operator=(const SequenceWriter&) = delete;
  // Moves the sequence's entries into `dir`; with `force`, an earlier sequence's entries of the
  // same names are replaced and other files stay.
  void Commit();
  // The checks of the constructor that need no writing (exists as a file, not empty): run them
  // before expensive work so that bad input fails early and leaves nothing behind.
  static void CheckTarget(const std::string& dir, bool force);

  void WriteFrame(double rgb_ts, double depth_ts, const cv::Mat& rgb, const cv::Mat& depth_u16,
                  const cv::Mat& mask) const;
  // rgb.txt, depth.txt, masks.txt, associations.txt, groundtruth.txt.
  void WriteIndex(const std::vector<double>& rgb_ts, const std::vector<double>& depth_ts,
                  const Trajectory& groundtruth) const;
  void WriteText(const std::string& name, const std::string& content) const;

  static std::string Stamp(double timestamp_s);  // "%.6f"
  // camera.yaml in the ORB-SLAM2 format dynorb reads.
  static std::string CameraYaml(const PinholeCamera& camera, double fps, double depth_factor);

  const std::string& dir() const { return final_dir_; }

 private:
  std::string final_dir_;
  std::optional<OutputFolder> folder_;  // `dir`, removed again if it was made and stays empty.
  std::string dir_;                     // The staging folder written to.
  bool committed_ = false;
};

}  // namespace dynorb::synth
