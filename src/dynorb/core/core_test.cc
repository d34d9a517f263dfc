#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "dynorb/core/background_error.h"
#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"
#include "dynorb/core/stats.h"
#include "dynorb/core/text.h"

namespace dynorb {
namespace {

TEST(Rigid3d, ComposeAndInverse) {
  const Rigid3d b_from_a(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
                         Eigen::Vector3d(0.5, -1.0, 2.0));
  const Eigen::Vector3d p_in_a(0.1, 0.2, 0.3);
  const Eigen::Vector3d p_in_b = b_from_a * p_in_a;
  EXPECT_LT((b_from_a.Inverse() * p_in_b - p_in_a).norm(), 1e-12);
  const Rigid3d id = b_from_a * b_from_a.Inverse();
  EXPECT_LT(id.translation.norm(), 1e-12);
  EXPECT_LT(RotationAngleRad(id.rotation), 1e-9);
  EXPECT_LT((b_from_a.ToMatrix() * p_in_a.homogeneous()).head<3>().isApprox(p_in_b) ? 0 : 1, 1);
}

TEST(Rigid3d, RotationAngle) {
  EXPECT_NEAR(RotationAngleRad(Eigen::Quaterniond(Eigen::AngleAxisd(2.5, Eigen::Vector3d::UnitY()))), 2.5,
              1e-12);
  EXPECT_NEAR(RotationAngleRad(Eigen::Quaterniond(Eigen::AngleAxisd(1e-7, Eigen::Vector3d::UnitX()))), 1e-7,
              1e-15);
}

TEST(PinholeCamera, ProjectUnprojectRoundTrip) {
  const PinholeCamera cam = TumFreiburg3Camera();
  const Eigen::Vector3d p(0.3, -0.2, 2.0);
  const Eigen::Vector2d uv = cam.Project(p);
  EXPECT_NEAR(uv.x(), 535.4 * 0.15 + 320.1, 1e-12);
  EXPECT_LT((cam.Unproject(uv, 2.0) - p).norm(), 1e-12);
}

TEST(Stats, MatchesNumpyDefinitions) {
  const SummaryStats s = Summarize({1.0, 2.0, 3.0, 4.0});
  EXPECT_EQ(s.count, 4);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.stddev, std::sqrt(1.25));
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.p95, 3.85);
  EXPECT_EQ(Summarize({}).count, 0);
}

TEST(TrimBlanks, StripsSpacesTabsAndLineEndsOnBothSidesOnly) {
  EXPECT_EQ(TrimBlanks("  person \t\r\n"), "person");
  EXPECT_EQ(TrimBlanks("traffic light"), "traffic light");
  EXPECT_EQ(TrimBlanks("\t a b \n"), "a b");
  EXPECT_EQ(TrimBlanks(" \t\r\n"), "");
  EXPECT_EQ(TrimBlanks(""), "");
}

TEST(BackgroundError, KeepsTheFirstExceptionOfABackgroundThreadForItsOwner) {
  BackgroundError error;
  EXPECT_TRUE(error.Capture([] {}));
  EXPECT_FALSE(error.failed());
  EXPECT_NO_THROW(error.Rethrow());
  bool first = false, second = false;
  std::thread worker([&] {
    first = error.Capture([] { throw std::runtime_error("mapper: first"); });
    second = error.Capture([] { throw std::out_of_range("mapper: second"); });
  });
  worker.join();  // Without Capture the exception would have ended the process.
  EXPECT_FALSE(first);
  EXPECT_FALSE(second);
  EXPECT_TRUE(error.failed());
  for (int call = 0; call < 2; ++call) {  // Every call rethrows the first one.
    try {
      error.Rethrow();
      ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "mapper: first");
    }
  }
}

}  // namespace
}  // namespace dynorb
