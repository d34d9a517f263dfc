// A synthetic sequence appears complete or not at all (SequenceWriter's staging folder), and the
// generator refuses inputs that cannot give a valid sequence before it writes.
#include "dynorb/synth/sequence_writer.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>

#include "dynorb/core/error.h"
#include "dynorb/io/test_temp_dir.h"
#include "dynorb/synth/camera_motion.h"
#include "dynorb/synth/synthesizer.h"

namespace dynorb::synth {
namespace {
namespace fs = std::filesystem;

class SequenceWriterTest : public testing::TempDirTest {
 protected:
  SequenceWriterTest() : TempDirTest("dynorb_writer_test_") {}
  void WriteOneFrame(const SequenceWriter& writer, double ts) {
    const cv::Mat rgb(4, 4, CV_8UC3, cv::Scalar(1, 2, 3)), depth(4, 4, CV_16U, cv::Scalar(5000)),
        mask(4, 4, CV_8U, cv::Scalar(0));
    writer.WriteFrame(ts, ts + 0.001, rgb, depth, mask);
  }
  size_t Entries(const fs::path& dir) {
    return static_cast<size_t>(
        std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
  }
};

TEST_F(SequenceWriterTest, AFailedGenerationLeavesNothing) {
  const fs::path out = dir_ / "seq";
  {
    SequenceWriter writer(out.string(), false);
    WriteOneFrame(writer, 1.0);
    writer.WriteText("rgb.txt", "1.000000 rgb/1.000000.png\n");
    EXPECT_FALSE(fs::exists(out / "rgb.txt") || fs::exists(out / "rgb"))
        << "nothing at the final names before Commit()";
  }
  EXPECT_EQ(Entries(dir_), 0u) << "no staging folder left either";
}

TEST_F(SequenceWriterTest, CommitMovesTheSequenceIntoPlace) {
  const fs::path out = dir_ / "seq";
  fs::create_directories(out);  // An empty folder is allowed without --force.
  {
    SequenceWriter writer((out.string() + "/"), false);
    WriteOneFrame(writer, 1.0);
    writer.WriteText("rgb.txt", "new\n");
    writer.Commit();
  }
  EXPECT_TRUE(fs::is_regular_file(out / "rgb" / "1.000000.png"));
  EXPECT_TRUE(fs::is_regular_file(out / "depth" / "1.001000.png"));
  EXPECT_TRUE(fs::is_regular_file(out / "rgb.txt"));
  EXPECT_EQ(Entries(dir_), 1u);
}

TEST_F(SequenceWriterTest, ForceReplacesAnEarlierSequenceOnlyOnCommit) {
  const fs::path out = dir_ / "seq";
  {
    SequenceWriter writer(out.string(), false);
    WriteOneFrame(writer, 1.0);
    WriteOneFrame(writer, 2.0);
    writer.WriteText("rgb.txt", "old\n");
    writer.WriteText("scene.yaml", "old\n");
    writer.Commit();
  }
  std::ofstream(out / "notes.txt") << "the user's own file";
  {
    SequenceWriter writer(out.string(), true);
    WriteOneFrame(writer, 3.0);
    // Failed here: the earlier sequence is untouched.
  }
  EXPECT_TRUE(fs::exists(out / "rgb" / "2.000000.png"));
  EXPECT_FALSE(fs::exists(out / "rgb" / "3.000000.png"));
  {
    SequenceWriter writer(out.string(), true);
    WriteOneFrame(writer, 3.0);
    writer.WriteText("rgb.txt", "new\n");
    writer.Commit();
  }
  EXPECT_EQ(Entries(out / "rgb"), 1u) << "no frame of the earlier sequence mixed in";
  EXPECT_TRUE(fs::exists(out / "rgb" / "3.000000.png"));
  std::ifstream rgb(out / "rgb.txt");
  std::string line;
  std::getline(rgb, line);
  EXPECT_EQ(line, "new");
  EXPECT_TRUE(fs::exists(out / "notes.txt"));
  EXPECT_EQ(Entries(dir_), 1u);
}

// The staging folder lives inside the output folder: an output reached through a symbolic link
// works (a sibling staging folder was on the link's file system, not the target's), and a killed
// generation's staging folder neither blocks nor stays.
TEST_F(SequenceWriterTest, StagingInsideTheOutputFolder) {
  fs::create_directories(dir_ / "real");
  fs::create_directory_symlink(dir_ / "real", dir_ / "link");
  fs::create_directories(dir_ / "real" / ".partial-999999999" / "rgb");  // No such process.
  {
    SequenceWriter writer((dir_ / "link").string(), false);
    EXPECT_FALSE(fs::exists(dir_ / "real" / ".partial-999999999")) << "stale staging folder kept";
    WriteOneFrame(writer, 1.0);
    writer.Commit();
  }
  EXPECT_TRUE(fs::is_regular_file(dir_ / "real" / "rgb" / "1.000000.png"));
  EXPECT_TRUE(fs::is_symlink(dir_ / "link"));
  EXPECT_EQ(Entries(dir_ / "real"), 3u);  // rgb, depth, masks; no staging folder.
}

TEST_F(SequenceWriterTest, DuplicateOrLongTimestampsAreRefusedBeforeWriting) {
  // Two rgb frames paired with one depth image would share its file.
  std::ofstream(dir_ / "associations.txt") << "100.000 rgb/a.png 100.010 depth/a.png\n"
                                              "100.033 rgb/b.png 100.010 depth/a.png\n";
  try {
    ReadFrameTimes((dir_ / "associations.txt").string(), 99.0, 10.0);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("associations.txt:2: depth timestamps must increase"),
              std::string::npos)
        << e.what();
  }
  std::ofstream(dir_ / "associations.txt") << "100.0000001 rgb/a.png 100.01 depth/a.png\n"
                                              "100.0000003 rgb/b.png 100.02 depth/b.png\n";
  EXPECT_THROW(ReadFrameTimes((dir_ / "associations.txt").string(), 99.0, 10.0), InputError);
  // A trajectory of 1e8 s would be 3e9 frames at 30 Hz (the frame count overflowed an int).
  fs::create_directories(dir_ / "long");  // No associations.txt next to it: 30 Hz frames.
  std::ofstream(dir_ / "long" / "groundtruth.txt") << "0 0 0 0 0 0 0 1\n100000000 0 0 1 0 0 0 1\n";
  SynthOptions o;
  o.trajectory_file = (dir_ / "long" / "groundtruth.txt").string();
  o.out_dir = (dir_ / "seq").string();
  o.people_dir.clear();
  try {
    Synthesize(o);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frames at 30 Hz (pass --frames N)"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir_ / "seq"));
}

}  // namespace
}  // namespace dynorb::synth
