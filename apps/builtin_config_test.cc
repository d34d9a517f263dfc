#include "builtin_config.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

namespace dynorb {
namespace {

std::string ReadSource(const std::string& relative) {
  std::ifstream in(std::string(DYNORB_SOURCE_DIR) + "/" + relative);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(BuiltInConfig, TheFolderNameChoosesTheTumCameraAndTheTextIsTheCheckoutsFile) {
  for (int k = 1; k <= 3; ++k) {
    const std::string folder = "/data/rgbd_dataset_freiburg" + std::to_string(k) + "_walking_xyz";
    for (const std::string& path :
         {folder, folder + "/",
          std::string("rgbd_dataset_freiburg") + std::to_string(k) + "_desk"}) {
      const std::optional<BuiltInConfig> c = BuiltInConfigForDataset(path);
      ASSERT_TRUE(c.has_value()) << path;
      EXPECT_EQ(c->file, "config/tum_fr" + std::to_string(k) + ".yaml");
      EXPECT_EQ(c->camera, "TUM RGB-D freiburg" + std::to_string(k));
      const std::string source = ReadSource(c->file);
      ASSERT_FALSE(source.empty());
      EXPECT_EQ(c->yaml, source) << "the built-in text differs from " << c->file;
    }
  }
}

TEST(BuiltInConfig, RelativeNamesStandForTheFolderTheyName) {
  EXPECT_EQ(BuiltInConfigForDataset("/data/rgbd_dataset_freiburg2_desk/sub/..")->file,
            "config/tum_fr2.yaml");
  const std::filesystem::path before = std::filesystem::current_path();
  const std::filesystem::path folder = std::filesystem::temp_directory_path() /
                                       ("rgbd_dataset_freiburg1_cwd_" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder);
  std::filesystem::current_path(folder);
  const std::optional<BuiltInConfig> here = BuiltInConfigForDataset(".");
  std::filesystem::current_path(before);
  std::filesystem::remove_all(folder);
  ASSERT_TRUE(here.has_value());
  EXPECT_EQ(here->file, "config/tum_fr1.yaml");
}

TEST(BuiltInConfig, NoGuessWithoutOrWithTwoCameraNames) {
  EXPECT_FALSE(BuiltInConfigForDataset("/data/rgbd_bonn_balloon").has_value());
  EXPECT_FALSE(BuiltInConfigForDataset("/data/office").has_value());
  EXPECT_FALSE(BuiltInConfigForDataset("/data/freiburg1_vs_freiburg3").has_value());
  // Only the folder's own name counts, not its parents'.
  EXPECT_FALSE(
      BuiltInConfigForDataset("/data/rgbd_dataset_freiburg3_walking_xyz/copy").has_value());
}

}  // namespace
}  // namespace dynorb
