// TumSequence: streaming reader of a TUM RGB-D (or Bonn RGB-D Dynamic) sequence folder.
//
// Folder layout: rgb.txt and depth.txt ("timestamp relative/path.png"), optional groundtruth.txt
// (TUM trajectory, world_from_cam). Alternatively an explicit associations file
// ("rgb_ts rgb/x.png depth_ts depth/x.png", ORB-SLAM2 style) replaces rgb.txt/depth.txt.
// rgb and depth are associated one-to-one with associate.py's greedy rule (association.h).
//
// Owns only the list of associated stamps/paths and the ground truth; images are read from disk
// on demand by Frame(i)/Next(), so sequences of any length stream in constant memory.
// Thread-safety: Frame() is const and may be called concurrently; Next()/Rewind() are not.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "dynorb/core/trajectory.h"
#include "dynorb/io/association.h"

namespace dynorb {

struct TumSequenceOptions {
  // Raw 16-bit depth units per metre (5000 for TUM RGB-D and Bonn; ORB-SLAM2 DepthMapFactor).
  double depth_factor = 5000.0;
  // rgb/depth association window in seconds (associate.py --max_difference).
  double max_difference_s = 0.02;
  // Added to depth stamps before association (associate.py --offset).
  double offset_s = 0.0;
  // Associations file; empty = associate rgb.txt with depth.txt. Relative paths are resolved
  // against the sequence folder.
  std::string associations_file;
  // Read groundtruth.txt when the folder has one.
  bool load_ground_truth = true;
  // Check at construction that every referenced image file exists (one stat per image).
  bool check_images_exist = false;
  // Throws InputError for non-positive/non-finite factors or windows.
  void Validate() const;
};

// One RGB-D frame. `rgb` is 8-bit BGR (CV_8UC3); `depth_m` is CV_32FC1 in metres, 0 = no depth,
// same size as `rgb`.
struct RgbdFrame {
  size_t index = 0;
  double timestamp_s = 0.0;  // rgb stamp: the frame's time
  double depth_timestamp_s = 0.0;
  cv::Mat rgb;
  cv::Mat depth_m;
};

class TumSequence {
 public:
  // Reads the lists (not the images) and associates. Throws InputError for a missing folder or
  // list file, malformed lines (file:line), non-increasing/duplicate stamps, no associations,
  // a malformed groundtruth.txt.
  explicit TumSequence(std::string folder, TumSequenceOptions options = {});

  size_t size() const { return entries_.size(); }
  const std::string& folder() const { return folder_; }
  const TumSequenceOptions& options() const { return options_; }
  // The associated stamps and paths (paths as written in the list files).
  const std::vector<AssociatedPair>& entries() const { return entries_; }

  // Loads frame i (i < size()). Throws InputError if an image is missing/unreadable, the depth
  // PNG is not 16-bit single channel, or depth and rgb sizes differ.
  RgbdFrame Frame(size_t i) const;
  // Loads the next frame into *frame; returns false at the end of the sequence.
  bool Next(RgbdFrame* frame);
  void Rewind() { next_index_ = 0; }

  bool HasGroundTruth() const { return ground_truth_.has_value(); }
  // Ground truth (world_from_cam); empty trajectory if the folder has none.
  const Trajectory& ground_truth() const;

  // Absolute path of a list entry (resolved against the folder).
  std::string ResolvePath(const std::string& relative) const;

 private:
  std::string folder_;
  TumSequenceOptions options_;
  std::vector<AssociatedPair> entries_;
  std::optional<Trajectory> ground_truth_;
  size_t next_index_ = 0;
};

}  // namespace dynorb
