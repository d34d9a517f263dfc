// BackgroundError: the first exception of work run on a background thread, kept for the thread
// that owns the work (an exception escaping a std::thread calls std::terminate). Thread-safe.
#pragma once

#include <exception>
#include <mutex>

namespace dynorb {

class BackgroundError {
 public:
  // Runs fn(). An exception it throws is kept (only the first one) instead of escaping; returns
  // whether fn() returned normally.
  template <typename Fn>
  bool Capture(Fn&& fn) noexcept {
    try {
      fn();
      return true;
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
      return false;
    }
  }
  bool failed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return static_cast<bool>(error_);
  }
  // Rethrows the kept exception, if any (again on every call: the failed work is not retried).
  void Rethrow() const {
    std::exception_ptr error;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      error = error_;
    }
    if (error) std::rethrow_exception(error);
  }

 private:
  mutable std::mutex mutex_;
  std::exception_ptr error_;
};

}  // namespace dynorb
