// Reprojection residual of a keypoint observation in an RGB-D (or monocular) frame.
//
// With point_in_cam p = R * point_in_world + t  (cam_from_world = [R | t]) and
//   u = fx * p.x / p.z + cx,   v = fy * p.y / p.z + cy,   u_r = u - bf / p.z,
// the residual is  r = sqrt(information) * (observed - predicted)  with 2 components (u, v) for a
// monocular observation or 3 (u, v, u_r) for an RGB-D observation with a virtual right
// coordinate u_r = u - bf / depth (ORB-SLAM2's stereo formulation of RGB-D). `information` is the
// inverse variance 1 / sigma^2 of the keypoint's pyramid level. When the observation carries a
// disparity information (KeypointObservation::disparity_information > 0), the third component is
// instead sqrt(disparity_information) * (d - bf / p.z) with the measured disparity d = u - u_r:
// the depth weighted by the depth sensor's own noise, independent of the keypoint's pixel noise.
// Jacobians are analytic (see .cc).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "dynorb/core/keypoint_observation.h"
#include "dynorb/core/pinhole_camera.h"

namespace ceres {
class CostFunction;
}

namespace dynorb {

// Parameter blocks: [pose (7, see pose_block.h), point_in_world (3)].
ceres::CostFunction* NewReprojectionCost(const PinholeCamera& camera, double bf, const KeypointObservation& obs);
// Parameter blocks: [pose (7)]; the point is held fixed.
ceres::CostFunction* NewPoseOnlyReprojectionCost(const PinholeCamera& camera, double bf,
                                                 const KeypointObservation& obs,
                                                 const Eigen::Vector3d& point_in_world);

// Parameter blocks: [pose (7)]; the residuals of every observation (2 or 3 each, in order) against
// its fixed point, stacked in one block: Ceres' per-block bookkeeping is paid once, which is what
// matters for small fits repeated many times. One point per observation (checked, aborts).
ceres::CostFunction* NewPoseOnlyBatchCost(const PinholeCamera& camera, double bf,
                                          std::vector<KeypointObservation> observations,
                                          std::vector<Eigen::Vector3d> points_in_world);

// chi^2 of the whitened residual above (the squared norm of r), for outlier gating.
// Returns +inf when the point is not in front of the camera.
double ReprojectionChi2(const PinholeCamera& camera, double bf, const KeypointObservation& obs,
                        const Eigen::Vector3d& point_in_cam);

}  // namespace dynorb
