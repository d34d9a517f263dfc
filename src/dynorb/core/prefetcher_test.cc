#include "dynorb/core/prefetcher.h"

#include <gtest/gtest.h>

#include <atomic>
#include <string>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

TEST(Prefetcher, DeliversEveryItemInOrder) {
  Prefetcher<std::string> p(
      50, [](size_t i) { return std::to_string(i * i); }, 3);
  for (size_t i = 0; i < 50; ++i) EXPECT_EQ(p.Next(), std::to_string(i * i));
  EXPECT_THROW(p.Next(), std::out_of_range);
}

TEST(Prefetcher, ErrorOfOneItemArrivesAfterTheItemsBeforeIt) {
  std::atomic<int> loads{0};
  Prefetcher<int> p(
      10,
      [&loads](size_t i) {
        ++loads;
        if (i == 4) throw InputError("frame 4 is corrupt");
        return static_cast<int>(i);
      },
      2);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(p.Next(), i);
  try {
    p.Next();
    FAIL() << "expected the loader's InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "frame 4 is corrupt");
  }
  EXPECT_THROW(p.Next(), std::logic_error);  // The loader stopped: no hang.
  EXPECT_EQ(loads.load(), 5);
}

TEST(Prefetcher, EarlyDestructionStopsTheLoader) {
  std::atomic<int> loads{0};
  {
    Prefetcher<int> p(
        1000000,
        [&loads](size_t i) {
          ++loads;
          return static_cast<int>(i);
        },
        2);
    EXPECT_EQ(p.Next(), 0);
  }  // Joins without loading the million items.
  EXPECT_LT(loads.load(), 10);
}

TEST(Prefetcher, ZeroItems) {
  Prefetcher<int> p(0, [](size_t) { return 1; });
  EXPECT_THROW(p.Next(), std::out_of_range);
}

}  // namespace
}  // namespace dynorb
