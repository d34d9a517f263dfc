#include "dynorb/io/text_lines.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "dynorb/core/error.h"
#include "dynorb/core/test_expect_error.h"
#include "dynorb/io/test_temp_dir.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;
using dynorb::testing::ExpectInputError;

double Parse(const std::string& text) { return ParseDouble(text, "f.txt", 3); }

TEST(ParseDouble, AcceptsDecimalNotation) {
  EXPECT_EQ(Parse("1"), 1.0);
  EXPECT_EQ(Parse("-1.5"), -1.5);
  EXPECT_EQ(Parse("+2"), 2.0);
  EXPECT_EQ(Parse(".5"), 0.5);
  EXPECT_EQ(Parse("5."), 5.0);
  EXPECT_EQ(Parse("1e3"), 1000.0);
  EXPECT_EQ(Parse("2.5E-3"), 0.0025);
  EXPECT_EQ(Parse("1341846313.592026"), 1341846313.592026);
  EXPECT_EQ(Parse("-0"), 0.0);
}

// An underflow is a valid number: the tiny (subnormal) or zero value, not an error.
TEST(ParseDouble, AcceptsUnderflowAsATinyOrZeroValue) {
  const double tiny = Parse("1e-320");
  EXPECT_GT(tiny, 0.0);
  EXPECT_LT(tiny, 1e-300);
  EXPECT_EQ(Parse("-1e-400"), 0.0);
  EXPECT_EQ(
      Parse("0.000000000000000000000000000000000000000000000000000000000000000000000001e-300"),
      0.0);
}

TEST(ParseDouble, RejectsAnythingButDecimalNotation) {
  for (const char* text : {"0x10", "0X1p3", "-0x1", "", "+", "-", ".", "e5", "1e", "1e+", "1.0.0",
                           "1,5", "1_000", "\v1", "1f", "x"}) {
    ExpectInputError([&] { Parse(text); }, std::string("f.txt:3: not a number: '"));
  }
  // A NUL inside the field: strtod stopped there and took "1.0".
  ExpectInputError([&] { Parse(std::string("1.0\0abc", 7)); },
                   "f.txt:3: not a number: '1.0\\x00abc'");
}

TEST(ParseDouble, RejectsNonFiniteValues) {
  for (const char* text : {"nan", "NaN", "-nan", "inf", "+Inf", "-infinity", "nan(0x1)"})
    ExpectInputError([&] { Parse(text); }, std::string("f.txt:3: non-finite value: '") + text);
  ExpectInputError([&] { Parse("1e999"); }, "f.txt:3: number out of range: '1e999'");
  ExpectInputError([&] { Parse("-1e309"); }, "number out of range");
}

class ForEachDataLineTest : public testing::TempDirTest {
 protected:
  ForEachDataLineTest() : TempDirTest("dynorb_text_lines_") {}
  // The fields of every data line of `path`.
  static std::vector<std::vector<std::string>> Lines(const std::string& path) {
    std::vector<std::vector<std::string>> lines;
    ForEachDataLine(path,
                    [&](int, const std::vector<std::string>& fields) { lines.push_back(fields); });
    return lines;
  }
};

TEST_F(ForEachDataLineTest, MissingFileAndDirectoryHaveTheirOwnMessages) {
  const std::string missing = (dir_ / "missing.txt").string();
  ExpectInputError([&] { Lines(missing); }, "file not found: " + missing);
  ExpectInputError([&] { Lines(dir_.string()); }, dir_.string() + " is a directory, not a file");
}

// `--est <(cat f)` names /dev/fd/63, a pipe: it reads like a file (it used to be "not found").
TEST_F(ForEachDataLineTest, ReadsAPipe) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const std::string text = "# comment\n1.0 2 3\n\n4,5,6\n";
  ASSERT_EQ(::write(fds[1], text.data(), text.size()), static_cast<ssize_t>(text.size()));
  ::close(fds[1]);
  const std::string path = "/dev/fd/" + std::to_string(fds[0]);
  std::vector<std::vector<std::string>> lines;
  EXPECT_NO_THROW(lines = Lines(path));
  ::close(fds[0]);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], (std::vector<std::string>{"1.0", "2", "3"}));
  EXPECT_EQ(lines[1], (std::vector<std::string>{"4", "5", "6"}));
}

// A character device is a stream too: /dev/null reads as an empty file.
TEST_F(ForEachDataLineTest, ReadsACharacterDevice) {
  if (!fs::exists("/dev/null")) GTEST_SKIP() << "no /dev/null";
  EXPECT_TRUE(Lines("/dev/null").empty());
}

}  // namespace
}  // namespace dynorb
