// FileMaskProvider: per-frame a-priori masks or boxes read from disk, so any offline segmenter
// (Mask R-CNN, ...) plugs into the semantic mode, and the synthetic ground truth serves as an
// oracle for ablations. Two list formats, one line per frame (# comments allowed):
//   masks:  "timestamp path/to/mask.png"  (8-bit PNG, nonzero = dynamic; the dataset's
//           masks.txt of `dynorb synth` is such a list -> oracle)
//   boxes:  "timestamp x y w h [class_id] [score]"  (image pixels; several lines per stamp
//           allowed; refined with depth like detector boxes)
// Paths are relative to the list's folder. A frame is matched to the nearest stamp within
// max_time_diff_s; a frame without an entry has no dynamic object.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "dynorb/dynamic/mask_provider.h"
#include "dynorb/dynamic/mask_refine.h"

namespace dynorb {

enum class MaskFileKind { kMasks, kBoxes };

class FileMaskProvider : public MaskProvider {
 public:
  // Parses the whole list (InputError with file:line for a malformed line, a missing PNG path).
  FileMaskProvider(const std::string& list_path, MaskFileKind kind, const DepthRefineOptions& refine,
                   double max_time_diff_s = 0.005);
  std::string name() const override { return kind_ == MaskFileKind::kMasks ? "file-masks" : "file-boxes"; }
  // InputError if a listed PNG cannot be read or has the wrong size/type.
  DynamicObjects Masks(const MaskQuery& query) override;
  size_t size() const { return kind_ == MaskFileKind::kMasks ? masks_.size() : boxes_.size(); }

 private:
  template <typename T>
  const T* Nearest(const std::map<double, T>& entries, double timestamp_s) const;

  std::string folder_;
  MaskFileKind kind_;
  DepthRefineOptions refine_;
  double max_time_diff_s_;
  std::map<double, std::string> masks_;
  std::map<double, std::vector<Detection>> boxes_;
};

}  // namespace dynorb
