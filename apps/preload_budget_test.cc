#include "preload_budget.h"

#include <gtest/gtest.h>

#include <string>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

TEST(PreloadBudget, CountsColourDepthAndMasks) {
  EXPECT_DOUBLE_EQ(PreloadBytes(10, 640, 480, false), 10.0 * 640 * 480 * 7);
  EXPECT_DOUBLE_EQ(PreloadBytes(10, 640, 480, true), 10.0 * 640 * 480 * 9);
  EXPECT_DOUBLE_EQ(PreloadBytes(0, 640, 480, true), 0.0);
}

TEST(PreloadBudget, RefusesMoreThanHalfTheMachineWithOneClearMessage) {
  EXPECT_NO_THROW(CheckPreloadFits(300, 4e9, 8e9));  // exactly half: accepted
  EXPECT_NO_THROW(CheckPreloadFits(300, 4e9, 0.0));  // unknown machine: accepted
  try {
    CheckPreloadFits(3000, 5.5e9, 8e9);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("--preload needs about 5.5 GB for 3000 frames"), std::string::npos) << what;
    EXPECT_NE(what.find("(8.0 GB)"), std::string::npos) << what;
    EXPECT_NE(what.find("--frames A:B"), std::string::npos) << what;
  }
}

TEST(PreloadBudget, ReadsThisMachinesMemory) {
  EXPECT_GT(PhysicalMemoryBytes(), 64e6);  // any machine that builds dynorb has more than 64 MB
}

}  // namespace
}  // namespace dynorb
