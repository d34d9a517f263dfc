#include "dynorb/io/point_cloud_io.h"

#include <filesystem>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "dynorb/core/error.h"
#include "dynorb/io/test_temp_dir.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;

class PointCloudIoTest : public testing::TempDirTest {
 protected:
  PointCloudIoTest() : TempDirTest("dynorb_ply_io_") {}
};

PointCloud ThreePoints() {
  PointCloud c;
  c.points = {{1.5f, -2.25f, 0.125f}, {0.f, 0.f, 3.f}, {-1e-3f, 42.f, 7.75f}};
  c.rgb = {{255, 0, 10}, {1, 2, 3}, {128, 64, 32}};
  c.flags.push_back({"dynamic_object_id", {1, 0, 0}});
  return c;
}

TEST_F(PointCloudIoTest, RoundTripsExactlyWithAStandardHeader) {
  const std::string path = (dir_ / "map.ply").string();
  WritePlyPointCloud(path, ThreePoints());
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment written by dynorb\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      "property uchar dynamic_object_id\nend_header\n";
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  ASSERT_EQ(bytes.size(), header.size() + 3 * 16);
  // 1.5f = 0x3FC00000, little-endian first.
  EXPECT_EQ(static_cast<unsigned char>(bytes[header.size() + 2]), 0xC0);
  EXPECT_EQ(static_cast<unsigned char>(bytes[header.size() + 3]), 0x3F);
  const PointCloud back = ReadPlyPointCloud(path);
  const PointCloud want = ThreePoints();
  ASSERT_EQ(back.points.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(back.points[i], want.points[i]) << i;
    EXPECT_EQ(back.rgb[i], want.rgb[i]) << i;
  }
  ASSERT_EQ(back.flags.size(), 1u);
  EXPECT_EQ(back.flags[0].first, "dynamic_object_id");
  EXPECT_EQ(back.flags[0].second, want.flags[0].second);
}

TEST_F(PointCloudIoTest, AnEmptyCloudIsAValidFile) {
  const std::string path = (dir_ / "empty.ply").string();
  WritePlyPointCloud(path, PointCloud());
  EXPECT_TRUE(ReadPlyPointCloud(path).points.empty());
}

TEST_F(PointCloudIoTest, BadCloudsAreRefusedAndLeaveNoFile) {
  const std::string path = (dir_ / "bad.ply").string();
  PointCloud c = ThreePoints();
  c.rgb.pop_back();
  EXPECT_THROW(WritePlyPointCloud(path, c), InputError);
  c = ThreePoints();
  c.flags[0].second.pop_back();
  EXPECT_THROW(WritePlyPointCloud(path, c), InputError);
  c = ThreePoints();
  c.flags[0].first = "Bad Name";
  EXPECT_THROW(WritePlyPointCloud(path, c), InputError);
  c.flags[0].first = "red";
  EXPECT_THROW(WritePlyPointCloud(path, c), InputError);
  c.flags[0].first = "a";
  c.flags.push_back({"a", {0, 0, 0}});
  EXPECT_THROW(WritePlyPointCloud(path, c), InputError);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_THROW(WritePlyPointCloud((dir_ / "no_such_dir" / "m.ply").string(), ThreePoints()),
               InputError);
}

TEST_F(PointCloudIoTest, ForeignOrDamagedFilesAreRefusedWithTheirName) {
  const std::string ascii =
      Write("ascii.ply",
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
            "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
            "end_header\n0 0 0 1 2 3\n");
  try {
    ReadPlyPointCloud(ascii);
    FAIL() << "ASCII PLY accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ascii.ply"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadPlyPointCloud(Write("text.ply", "hello\n")), InputError);
  EXPECT_THROW(ReadPlyPointCloud((dir_ / "missing.ply").string()), InputError);
  // Truncated: one byte of the last point missing.
  const std::string path = (dir_ / "cut.ply").string();
  WritePlyPointCloud(path, ThreePoints());
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  bytes.pop_back();
  EXPECT_THROW(ReadPlyPointCloud(Write("cut2.ply", bytes)), InputError);
  // A vertex count whose byte size wraps around 2^64 (2^60 points of 16 bytes, no data).
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1152921504606846976\nproperty float x\n"
      "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty "
      "uchar blue\n"
      "property uchar dynamic_object_id\nend_header\n";
  EXPECT_THROW(ReadPlyPointCloud(Write("huge.ply", header)), InputError);
  // A second element; a repeated property.
  EXPECT_THROW(ReadPlyPointCloud(Write("two.ply",
                                       "ply\nformat binary_little_endian 1.0\nelement vertex 0\n"
                                       "element vertex 0\nend_header\n")),
               InputError);
  std::string repeated = header;
  repeated.replace(repeated.find("1152921504606846976"), 19, "0");
  repeated.replace(repeated.find("dynamic_object_id"), 17, "red");
  EXPECT_THROW(ReadPlyPointCloud(Write("repeated.ply", repeated)), InputError);
  repeated.replace(repeated.find("property uchar red\nend"), 18, "property uchar ok");
  EXPECT_NO_THROW(ReadPlyPointCloud(Write("ok.ply", repeated)));
}

}  // namespace
}  // namespace dynorb
