#include "dynorb/io/frame_range.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

using ::testing::HasSubstr;

std::string ErrorOf(const std::string& text, size_t size = 100) {
  try {
    SelectFrames(text, size);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FrameRangeTest, SelectsHalfOpenRangesClampedToTheSequence) {
  EXPECT_EQ(SelectFrames("", 100), std::make_pair(size_t{0}, size_t{100}));
  EXPECT_EQ(SelectFrames("10:20", 100), std::make_pair(size_t{10}, size_t{20}));
  EXPECT_EQ(SelectFrames(":20", 100), std::make_pair(size_t{0}, size_t{20}));
  EXPECT_EQ(SelectFrames("90:", 100), std::make_pair(size_t{90}, size_t{100}));
  EXPECT_EQ(SelectFrames("90:500", 100), std::make_pair(size_t{90}, size_t{100}));
  EXPECT_EQ(SelectFrames(":", 100), std::make_pair(size_t{0}, size_t{100}));
  const FrameRange open = ParseFrameRange("7:");
  EXPECT_EQ(open.first, 7u);
  EXPECT_FALSE(open.last.has_value());
}

TEST(FrameRangeTest, BadTextIsNamedWithoutKnowingTheSequence) {
  EXPECT_THAT(ErrorOf("abc"), HasSubstr("--frames expects A:B (e.g. 0:300 or 100:), got 'abc'"));
  EXPECT_THAT(ErrorOf("a:5"), HasSubstr("--frames: not a frame index: 'a'"));
  EXPECT_THAT(ErrorOf("5:x"), HasSubstr("not a frame index: 'x'"));
  EXPECT_THAT(ErrorOf("-1:5"), HasSubstr("not a frame index: '-1'"));
  EXPECT_THAT(ErrorOf("1:99999999999999999999999"), HasSubstr("not a frame index"));
  EXPECT_THAT(ErrorOf("3:3"), HasSubstr("--frames 3:3 selects no frame"));
  EXPECT_THAT(ErrorOf("9:2"), HasSubstr("selects no frame"));
  try {
    ParseFrameRange("abc", "'frames'");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("'frames' expects A:B"));
  }
}

TEST(FrameRangeTest, ARangeBeyondTheSequenceSelectsNothing) {
  EXPECT_THAT(ErrorOf("100:", 100),
              HasSubstr("--frames 100: selects no frame of a 100-frame sequence"));
  EXPECT_THAT(ErrorOf("", 0), HasSubstr("selects no frame of a 0-frame sequence"));
}

}  // namespace
}  // namespace dynorb
