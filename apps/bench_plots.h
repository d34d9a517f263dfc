// Figures of `dynorb bench`: the trajectory figure of one run (top/side view against ground
// truth and the ATE error over time, eval/plot.h) and a strip of keypoint overlays (kept green,
// removed red) from a few frames. Pure file-in/file-out helpers; thread-compatible.
#pragma once

#include <string>

namespace dynorb {

// Evaluates run_dir/trajectory.txt against dataset/groundtruth.txt (cropped to the run's time
// span) and writes `stem`.png and `stem`.svg. Returns false (writes nothing) when there is no
// ground truth or too few poses to align.
bool WriteTrajectoryPlot(const std::string& dataset, const std::string& run_dir,
                         const std::string& stem, const std::string& title);

// Picks `count` evenly spaced images of overlay_dir (*.png, sorted), halves them and writes them
// side by side to `path` (PNG) with their file names. Returns false if the folder has no image.
bool WriteKeypointStrip(const std::string& overlay_dir, const std::string& path, int count = 4);

// A picture of run_dir/map.ply (`dynorb run --save-map`) seen from behind the first keyframe of
// run_dir/keyframes.txt (1 m back along its optical axis, a wide 640x480 view), two panels: the
// landmarks in their colours, and the same in grey with those on dynamic objects of the masks
// (dynamic_object_id != 0) in red. Writes a PNG to `path`; returns false (writes nothing) when the
// run has no map.ply or no keyframe.
bool WriteMapView(const std::string& run_dir, const std::string& path, const std::string& title);

}  // namespace dynorb
