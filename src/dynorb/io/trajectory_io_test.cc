#include "dynorb/io/trajectory_io.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "dynorb/core/error.h"
#include "dynorb/io/atomic_file.h"
#include "dynorb/io/test_temp_dir.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;

class TrajectoryIoTest : public testing::TempDirTest {
 protected:
  TrajectoryIoTest() : TempDirTest("dynorb_traj_io_") {}
};

TEST_F(TrajectoryIoTest, RoundTrip) {
  Trajectory t;
  for (int i = 0; i < 5; ++i) {
    StampedPose p;
    p.timestamp_s = 1341846313.592026 + 0.033 * i;
    p.world_from_cam = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitZ())),
                               Eigen::Vector3d(0.1 * i, -0.2, 1.5));
    t.push_back(p);
  }
  const std::string path = (dir_ / "t.txt").string();
  WriteTumTrajectory(path, t);
  const Trajectory r = ReadTumTrajectory(path);
  ASSERT_EQ(r.size(), t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    EXPECT_NEAR(r[i].timestamp_s, t[i].timestamp_s, 1e-6);
    EXPECT_LT((r[i].world_from_cam.translation - t[i].world_from_cam.translation).norm(), 1e-8);
    EXPECT_LT(r[i].world_from_cam.rotation.angularDistance(t[i].world_from_cam.rotation), 1e-8);
  }
}

TEST_F(TrajectoryIoTest, CommentsBlankLinesAndCommas) {
  const Trajectory r = ReadTumTrajectory(Write("a.txt", "# header\n\n1.0 0 0 0 0 0 0 1\n2.0,1,2,3,0,0,0,1\n"));
  ASSERT_EQ(r.size(), 2u);
  EXPECT_DOUBLE_EQ(r[1].world_from_cam.translation.z(), 3.0);
}

TEST_F(TrajectoryIoTest, RejectsBadInputWithLineNumbers) {
  auto expect_error = [&](const std::string& content, const std::string& needle) {
    const std::string path = Write("bad.txt", content);
    try {
      ReadTumTrajectory(path);
      FAIL() << "no error for: " << content;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error("1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 1\n", "bad.txt:2: expected 8 values");
  expect_error("1.0 0 0 nan 0 0 0 1\n", "bad.txt:1: non-finite");
  expect_error("1.0 0 0 x 0 0 0 1\n", "not a number");
  expect_error("1.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n", "bad.txt:2: duplicate timestamp");
  expect_error("2.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n", "not increasing");
  expect_error("1.0 0 0 0 0 0 0 3\n", "not unit length");
  expect_error("1.0 0 0 0 0 0 0 1\n2.0 1e308 0 0 0 0 0 1\n",
               "bad.txt:2: position '1e308' is beyond");
  expect_error("1.0 0 -2e9 0 0 0 0 1\n", "bad.txt:1: position '-2e9' is beyond");
  expect_error("# only a comment\n", "no poses");
  EXPECT_THROW(ReadTumTrajectory((dir_ / "missing.txt").string()), InputError);
}

TEST_F(TrajectoryIoTest, DuplicateTimestampsCanKeepTheLastPose) {
  const std::string path = Write("dup.txt", "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n2.0 2 0 0 0 0 0 1\n3.0 3 0 0 0 0 0 1\n");
  EXPECT_THROW(ReadTumTrajectory(path), InputError);
  TrajectoryReadOptions options;
  options.keep_last_of_duplicate_timestamps = true;
  const Trajectory r = ReadTumTrajectory(path, options);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[1].timestamp_s, 2.0);
  EXPECT_EQ(r[1].world_from_cam.translation.x(), 2.0);
  EXPECT_EQ(ReadTumGroundTruth(path).size(), 3u);
  // Decreasing stamps are still rejected.
  EXPECT_THROW(ReadTumTrajectory(Write("dec.txt", "2.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n"), options),
               InputError);
}

// Some editors start a file with a UTF-8 byte order mark: it is not part of the first line.
TEST_F(TrajectoryIoTest, ReadsAFileThatStartsWithAByteOrderMark) {
  for (const char* first : {"# timestamp tx ty tz qx qy qz qw\n", ""}) {
    const fs::path path = dir_ / "bom.txt";
    std::ofstream(path) << "\xEF\xBB\xBF" << first << "1.0 1 2 3 0 0 0 1\n2.0 1 2 3 0 0 0 1\n";
    const Trajectory t = ReadTumTrajectory(path.string());
    ASSERT_EQ(t.size(), 2u) << first;
    EXPECT_EQ(t[0].timestamp_s, 1.0);
  }
}

// A pose too large for the line buffer (|t| ~ 1e300) used to be written cut short: a file no
// reader takes back. Now the write fails and leaves nothing.
TEST_F(TrajectoryIoTest, RefusesToWriteAPoseTooLargeForTheFormat) {
  StampedPose pose;
  pose.timestamp_s = 1.0;
  pose.world_from_cam.translation = Eigen::Vector3d(1e300, 0.0, 0.0);
  const fs::path path = dir_ / "huge.txt";
  EXPECT_THROW(WriteTumTrajectory(path.string(), {pose}), InputError);
  EXPECT_FALSE(fs::exists(path));
}

// An output path that is a directory is refused before anything is written.
TEST_F(TrajectoryIoTest, AnOutputThatIsADirectoryIsRefusedUpFront) {
  fs::create_directories(dir_ / "stats.json");
  EXPECT_THROW(CheckOutputTargets({(dir_ / "a.txt").string(), (dir_ / "stats.json").string()}),
               InputError);
  EXPECT_NO_THROW(CheckOutputTargets({(dir_ / "a.txt").string()}));
  EXPECT_THROW(AtomicFile((dir_ / "stats.json").string()), InputError);
  EXPECT_FALSE(fs::exists(dir_ / "a.txt"));
}

TEST_F(TrajectoryIoTest, FailedWriteLeavesNoFile) {
  EXPECT_THROW(WriteTumTrajectory((dir_ / "no_such_dir" / "t.txt").string(), {}), InputError);
  EXPECT_FALSE(fs::exists(dir_ / "no_such_dir"));
}

TEST_F(TrajectoryIoTest, AtomicFileWithoutCommitLeavesNothing) {
  const fs::path target = dir_ / "out.txt";
  {
    AtomicFile file(target.string());
    file.stream() << "partial";
  }
  EXPECT_FALSE(fs::exists(target));
  EXPECT_TRUE(fs::is_empty(dir_));
}

}  // namespace
}  // namespace dynorb
