#include "dynorb/synth/movers.h"

#include <gtest/gtest.h>

#include <cmath>

namespace dynorb::synth {
namespace {

TEST(KeyframePath, RestIntervalsAndTheirEnds) {
  KeyframePath path;
  path.Add(0.0, Eigen::Vector3d(0, 0, 0));
  path.Wait(1.0);                                   // rest [0, 1]
  path.MoveTo(Eigen::Vector3d(2, 0, 0), 1.0);       // walk [1, 3]
  path.Wait(0.5);                                   // rest [3, 3.5]
  path.Wait(0.5);                                   // ... still resting until 4
  path.MoveTo(Eigen::Vector3d(2, 1, 0), 1.0);       // walk [4, 5], then rest forever
  EXPECT_DOUBLE_EQ(path.RestSince(0.5), 0.0);
  EXPECT_TRUE(std::isnan(path.RestSince(2.0)));
  EXPECT_DOUBLE_EQ(path.RestSince(3.9), 3.0);       // two wait segments form one rest
  EXPECT_DOUBLE_EQ(path.RestSince(7.0), 5.0);
  EXPECT_DOUBLE_EQ(path.LastRestEnd(2.0), 1.0);
  EXPECT_DOUBLE_EQ(path.LastRestEnd(4.5), 4.0);
  EXPECT_TRUE(std::isnan(path.LastRestEnd(0.0)));
}

// A person standing still is a rigid object even while the camera moves: their card keeps the
// orientation it had when they stopped (objects.txt calls them still). Walking, it faces the camera.
TEST(Movers, PeopleAtRestDoNotTurnWithTheCamera) {
  Office office;
  office.walk_x0 = 0.5;
  office.walk_x1 = 5.5;
  office.walk_y0 = 2.0;
  office.walk_y1 = 2.5;
  office.pushed_box_start = Eigen::Vector3d(1, 3, 0);
  office.desk_item_start = Eigen::Vector3d(2, 4, 0.7);
  Texture sprite;
  sprite.levels = {cv::Mat(64, 32, CV_8UC3, cv::Scalar(90, 90, 90))};
  sprite.alpha_bulge = cv::Mat(64, 32, CV_32FC2, cv::Scalar(1.f, 0.f));
  const Movers movers(office, false, 1, 20.0, 3, {PersonLook{{&sprite}, "grey"}});
  // A camera sweeping sideways 2 m in front of the walking area.
  auto camera_at = [](double t) { return Eigen::Vector3d(0.5 + 0.2 * t, 0.0, 1.4); };
  int rest_frames = 0, walk_frames = 0;
  for (double t = 0.0; t < 20.0; t += 0.25) {
    std::vector<DrawQuad> now, later;
    movers.AppendQuads(t, camera_at, &now);
    movers.AppendQuads(t + 0.1, camera_at, &later);
    const bool still = !movers.States(t)[0].moving && !movers.States(t + 0.1)[0].moving &&
                       !movers.States(t + 0.05)[0].moving;
    const Eigen::Vector3d du = now[0].axis_u - later[0].axis_u;
    const Eigen::Vector3d d_origin = now[0].origin - later[0].origin;
    if (still) {
      ++rest_frames;
      EXPECT_LT(du.norm() + d_origin.norm(), 1e-9) << "t = " << t;
    } else {
      // Walking: the card's normal points at the camera.
      const Eigen::Vector3d centre = now[0].origin + 0.5 * now[0].axis_u;
      const Eigen::Vector2d to_cam = (camera_at(t) - centre).head<2>().normalized();
      const Eigen::Vector2d across = now[0].axis_u.head<2>().normalized();
      if (movers.States(t - kTurnBackS)[0].moving) {
        ++walk_frames;
        EXPECT_LT(std::abs(to_cam.dot(across)), 1e-6) << "t = " << t;
      }
    }
  }
  EXPECT_GT(rest_frames, 4);
  EXPECT_GT(walk_frames, 4);
}

}  // namespace
}  // namespace dynorb::synth
