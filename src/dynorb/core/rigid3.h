// Rigid3d: a rigid-body transform (rotation as unit quaternion + translation).
//
// Naming convention (frames in names): `b_from_a` maps a point expressed in frame a into frame b,
//   point_in_b = b_from_a * point_in_a = b_from_a.rotation * point_in_a + b_from_a.translation.
// Composition: c_from_a = c_from_b * b_from_a. A TUM trajectory line stores world_from_cam.
// Value type, no ownership, thread-compatible.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace dynorb {

struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) : rotation(q.normalized()), translation(t) {}
  Rigid3d(const Eigen::Matrix3d& r, const Eigen::Vector3d& t) : rotation(Eigen::Quaterniond(r).normalized()), translation(t) {}

  static Rigid3d Identity() { return Rigid3d(); }
  // From a 4x4 (or 3x4 top rows) homogeneous matrix.
  static Rigid3d FromMatrix(const Eigen::Matrix4d& m) {
    return Rigid3d(Eigen::Matrix3d(m.topLeftCorner<3, 3>()), Eigen::Vector3d(m.topRightCorner<3, 1>()));
  }

  Rigid3d Inverse() const {
    const Eigen::Quaterniond inv = rotation.conjugate();
    return Rigid3d(inv, -(inv * translation));
  }
  Eigen::Matrix4d ToMatrix() const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = rotation.toRotationMatrix();
    m.topRightCorner<3, 1>() = translation;
    return m;
  }
  Eigen::Matrix<double, 3, 4> ToMatrix3x4() const { return ToMatrix().topRows<3>(); }

  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const { return rotation * point + translation; }
  Rigid3d operator*(const Rigid3d& other) const {
    return Rigid3d(rotation * other.rotation, rotation * other.translation + translation);
  }
};

// Rotation angle of a relative rotation in radians, in [0, pi].
double RotationAngleRad(const Eigen::Quaterniond& q);

}  // namespace dynorb
