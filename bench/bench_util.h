// Helpers shared by the micro-benchmarks (bench/*_bench.cc).
#pragma once

#include <ctime>

#include <opencv2/core/utility.hpp>

namespace dynorb {

// OpenCV limited to `threads` threads (cv::setNumThreads) while this object lives, restored after;
// threads <= 0 leaves the setting as it is.
class CvThreads {
 public:
  explicit CvThreads(int threads) : saved_(cv::getNumThreads()), set_(threads > 0) {
    if (set_) cv::setNumThreads(threads);
  }
  ~CvThreads() {
    if (set_) cv::setNumThreads(saved_);
  }
  CvThreads(const CvThreads&) = delete;
  CvThreads& operator=(const CvThreads&) = delete;

 private:
  int saved_;
  bool set_;
};

// CPU time of the whole process since construction (std::clock: OpenCV's worker threads count
// too, where Google Benchmark's CPU column counts only the calling thread).
class ProcessCpuTimer {
 public:
  double ElapsedMs() const {
    return 1000.0 * static_cast<double>(std::clock() - start_) / CLOCKS_PER_SEC;
  }

 private:
  std::clock_t start_ = std::clock();
};

}  // namespace dynorb
