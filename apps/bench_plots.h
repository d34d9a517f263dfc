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

}  // namespace dynorb
