// ProgressBar for long subcommands: redraws one line on a terminal; on a non-terminal (CI logs)
// prints a line every 10 %. Writes to stderr. Not thread-safe.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace dynorb {

class ProgressBar {
 public:
  ProgressBar(std::string unit, int total) : unit_(std::move(unit)), total_(total), tty_(isatty(fileno(stderr)) != 0) {}

  // `extra` is appended (e.g. "31.2 Hz"). Call with done == total at the end.
  void Update(int done, const std::string& extra = "") {
    const int percent = total_ > 0 ? static_cast<int>(100LL * done / total_) : 100;
    const auto now = std::chrono::steady_clock::now();
    if (tty_) {
      if (done != total_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
    } else if (percent / 10 == last_percent_ / 10 && done != total_) {
      return;
    }
    last_draw_ = now;
    last_percent_ = percent;
    const int width = 30, filled = width * percent / 100;
    std::fprintf(stderr, "%s[%s%s] %d/%d %s %s%s", tty_ ? "\r" : "", std::string(filled, '#').c_str(),
                 std::string(width - filled, '.').c_str(), done, total_, unit_.c_str(), extra.c_str(),
                 tty_ ? "\033[K" : "\n");
    if (tty_ && done == total_) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }

 private:
  std::string unit_;
  int total_;
  bool tty_;
  int last_percent_ = -100;
  std::chrono::steady_clock::time_point last_draw_{};
};

}  // namespace dynorb
