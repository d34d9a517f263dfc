#include "dynorb/io/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "dynorb/core/error.h"
#include "dynorb/io/test_temp_dir.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;

class OutputFolderTest : public testing::TempDirTest {
 protected:
  OutputFolderTest() : TempDirTest("dynorb_output_folder_") {}
};

TEST_F(OutputFolderTest, AFailedCommandRemovesTheEmptyFoldersItCreated) {
  const fs::path out = dir_ / "a" / "b" / "run";
  {
    OutputFolder folder(out.string());
    EXPECT_TRUE(fs::is_directory(out));
  }
  EXPECT_FALSE(fs::exists(dir_ / "a"));             // Every folder it made on the way.
  EXPECT_TRUE(fs::is_directory(dir_));              // Never one that was there before.
  { OutputFolder folder((dir_ / "c/").string()); }  // A trailing separator.
  EXPECT_FALSE(fs::exists(dir_ / "c"));
}

TEST_F(OutputFolderTest, KeptOrNotEmptyOrThereBeforeItStays) {
  {
    OutputFolder folder((dir_ / "kept").string());
    folder.Keep();
  }
  EXPECT_TRUE(fs::is_directory(dir_ / "kept"));
  {
    OutputFolder folder((dir_ / "x" / "run").string());
    std::ofstream(dir_ / "x" / "run" / "overlay.png") << "written before the failure";
  }
  EXPECT_TRUE(fs::exists(dir_ / "x" / "run" / "overlay.png"));
  {
    OutputFolder folder((dir_ / "y" / "run").string());
    std::ofstream(dir_ / "y" / "note.txt") << "a parent that is no longer empty";
  }
  EXPECT_FALSE(fs::exists(dir_ / "y" / "run"));
  EXPECT_TRUE(fs::exists(dir_ / "y" / "note.txt"));
  { OutputFolder folder(dir_.string()); }  // Existed before.
  EXPECT_TRUE(fs::is_directory(dir_));
}

TEST_F(OutputFolderTest, AFolderThatCannotBeCreatedIsAnInputErrorAndLeavesNothing) {
  std::ofstream(dir_ / "file") << "not a folder";
  EXPECT_THROW(OutputFolder((dir_ / "file").string()), InputError);
  EXPECT_TRUE(fs::is_regular_file(dir_ / "file"));
  try {
    OutputFolder folder((dir_ / "file" / "sub").string(), "overlay folder");
    ADD_FAILURE() << "created a folder under a file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create overlay folder"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(fs::is_regular_file(dir_ / "file"));
}

}  // namespace
}  // namespace dynorb
