#include "dynorb/io/tum_sequence.h"

#include <cmath>
#include <filesystem>

#include "dynorb/core/error.h"
#include "dynorb/io/rgbd_image_io.h"
#include "dynorb/io/trajectory_io.h"

namespace dynorb {
namespace {
namespace fs = std::filesystem;

void CheckRegularFile(const fs::path& path, const std::string& what) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(what + " not found: " + path.string());
}

}  // namespace

void TumSequenceOptions::Validate() const {
  if (!std::isfinite(depth_factor) || depth_factor <= 0.0) {
    throw InputError("dataset: depth_factor must be > 0, got " + std::to_string(depth_factor));
  }
  AssociationOptions{max_difference_s, offset_s}.Validate();
}

TumSequence::TumSequence(std::string folder, TumSequenceOptions options)
    : folder_(std::move(folder)), options_(std::move(options)) {
  options_.Validate();
  std::error_code ec;
  if (!fs::is_directory(folder_, ec)) throw InputError("sequence folder not found: " + folder_);
  const fs::path dir(folder_);
  if (!options_.associations_file.empty()) {
    const std::string path = ResolvePath(options_.associations_file);
    CheckRegularFile(path, "associations file");
    entries_ = ReadAssociationsFile(path);
  } else {
    const fs::path rgb_list = dir / "rgb.txt";
    const fs::path depth_list = dir / "depth.txt";
    CheckRegularFile(rgb_list, "rgb list");
    CheckRegularFile(depth_list, "depth list");
    const std::vector<StampedPath> rgb = ReadImageList(rgb_list.string());
    const std::vector<StampedPath> depth = ReadImageList(depth_list.string());
    try {
      entries_ = AssociateImageLists(rgb, depth, {options_.max_difference_s, options_.offset_s});
    } catch (const InputError& e) {
      throw InputError(folder_ + ": " + e.what());
    }
  }
  if (options_.check_images_exist) {
    for (const AssociatedPair& pair : entries_) {
      CheckRegularFile(ResolvePath(pair.rgb_path), "rgb image");
      CheckRegularFile(ResolvePath(pair.depth_path), "depth image");
    }
  }
  const fs::path gt = dir / "groundtruth.txt";
  if (options_.load_ground_truth && fs::exists(gt, ec))
    ground_truth_ = ReadTumGroundTruth(gt.string());
}

std::string TumSequence::ResolvePath(const std::string& relative) const {
  const fs::path p(relative);
  return p.is_absolute() ? p.string() : (fs::path(folder_) / p).string();
}

RgbdFrame TumSequence::Frame(size_t i) const {
  if (i >= entries_.size()) {
    throw InputError("frame index " + std::to_string(i) + " out of range (sequence has " +
                     std::to_string(entries_.size()) + " frames)");
  }
  const AssociatedPair& pair = entries_[i];
  RgbdFrame frame;
  frame.index = i;
  frame.timestamp_s = pair.rgb_timestamp_s;
  frame.depth_timestamp_s = pair.depth_timestamp_s;
  const std::string rgb_path = ResolvePath(pair.rgb_path);
  const std::string depth_path = ResolvePath(pair.depth_path);
  frame.rgb = LoadColorImage(rgb_path);
  frame.depth_m = LoadDepthImageMetres(depth_path, options_.depth_factor);
  if (frame.rgb.size() != frame.depth_m.size()) {
    throw InputError("depth image size " + std::to_string(frame.depth_m.cols) + "x" +
                     std::to_string(frame.depth_m.rows) + " differs from rgb image size " +
                     std::to_string(frame.rgb.cols) + "x" + std::to_string(frame.rgb.rows) + ": " +
                     depth_path + " vs " + rgb_path);
  }
  return frame;
}

bool TumSequence::Next(RgbdFrame* frame) {
  if (next_index_ >= entries_.size()) return false;
  *frame = Frame(next_index_);
  ++next_index_;
  return true;
}

const Trajectory& TumSequence::ground_truth() const {
  static const Trajectory kEmpty;
  return ground_truth_ ? *ground_truth_ : kEmpty;
}

}  // namespace dynorb
