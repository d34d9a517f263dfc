// Prefetcher: loads items 0..count-1 with `load(i)` on one background thread, up to `capacity`
// ahead of the consumer, and hands them out in order. Used to decode the next frames' PNGs while
// the current frame is processed; the results are the same as loading inline (only the thread
// differs), so deterministic runs stay deterministic.
// An exception thrown by `load(i)` is rethrown by the i-th Next() (earlier items are delivered
// first); the loader stops after it. Destroying the prefetcher early stops and joins the thread.
// Next() must be called from one thread at a time.
#pragma once

#include <cstddef>
#include <exception>
#include <functional>
#include <stdexcept>
#include <thread>
#include <utility>

#include "dynorb/core/blocking_queue.h"

namespace dynorb {

template <typename T>
class Prefetcher {
 public:
  Prefetcher(size_t count, std::function<T(size_t)> load, size_t capacity = 4)
      : count_(count), load_(std::move(load)), queue_(capacity < 1 ? 1 : capacity) {
    thread_ = std::thread([this] { Run(); });
  }
  ~Prefetcher() {
    queue_.Close();
    thread_.join();
  }
  Prefetcher(const Prefetcher&) = delete;
  Prefetcher& operator=(const Prefetcher&) = delete;

  // The next item in order. Throws what its loader threw, or std::out_of_range past the end.
  T Next() {
    if (next_ >= count_) throw std::out_of_range("Prefetcher::Next past the last item");
    Slot slot;
    if (!queue_.Pop(&slot)) throw std::logic_error("Prefetcher closed");
    ++next_;
    if (slot.error) std::rethrow_exception(slot.error);
    return std::move(slot.value);
  }

 private:
  struct Slot {
    T value{};
    std::exception_ptr error;
  };

  void Run() {
    for (size_t i = 0; i < count_; ++i) {
      Slot slot;
      try {
        slot.value = load_(i);
      } catch (...) {
        slot.error = std::current_exception();
      }
      const bool failed = slot.error != nullptr;
      if (!queue_.Push(std::move(slot)) || failed) break;
    }
    queue_.Close();  // The consumer drains what is queued; a further Next() then fails cleanly.
  }

  const size_t count_;
  std::function<T(size_t)> load_;
  BlockingQueue<Slot> queue_;
  size_t next_ = 0;
  std::thread thread_;
};

}  // namespace dynorb
