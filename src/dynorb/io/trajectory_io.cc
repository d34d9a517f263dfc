#include "dynorb/io/trajectory_io.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "dynorb/core/error.h"
#include "dynorb/io/atomic_file.h"
#include "dynorb/io/text_lines.h"
#include "dynorb/io/timestamp_check.h"

namespace dynorb {
namespace {

// Positions beyond this are not metres of a camera path (the Moon is 3.8e8 m away); squared in
// the alignment and the error statistics they would overflow to inf.
constexpr double kMaxPositionM = 1e9;

}  // namespace

Trajectory ReadTumTrajectory(const std::string& path, const TrajectoryReadOptions& options) {
  Trajectory trajectory;
  ForEachDataLine(path, [&](int line_no, const std::vector<std::string>& fields) {
    if (fields.size() != 8) {
      throw InputErrorAt(path, line_no,
                         "expected 8 values 'timestamp tx ty tz qx qy qz qw', got " +
                             std::to_string(fields.size()));
    }
    double v[8];
    for (int i = 0; i < 8; ++i) v[i] = ParseDouble(fields[i], path, line_no);
    CheckTimestampRange(v[0], fields[0], path, line_no);
    for (int i = 1; i <= 3; ++i) {
      if (std::abs(v[i]) > kMaxPositionM) {
        throw InputErrorAt(
            path, line_no,
            "position '" + fields[i] + "' is beyond +-1e9 m: not a camera path in metres");
      }
    }
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    const double norm = q.norm();
    if (norm < 0.9 || norm > 1.1) {
      throw InputErrorAt(path, line_no, "quaternion is not unit length (|q| = " + std::to_string(norm) + ")");
    }
    const bool duplicate = !trajectory.empty() && v[0] == trajectory.back().timestamp_s;
    if (duplicate && options.keep_last_of_duplicate_timestamps) trajectory.pop_back();
    if (options.require_increasing_timestamps && !trajectory.empty() &&
        v[0] <= trajectory.back().timestamp_s) {
      throw InputErrorAt(path, line_no,
                         v[0] == trajectory.back().timestamp_s ? "duplicate timestamp"
                                                               : "timestamps are not increasing");
    }
    StampedPose pose;
    pose.timestamp_s = v[0];
    pose.world_from_cam = Rigid3d(q, Eigen::Vector3d(v[1], v[2], v[3]));
    trajectory.push_back(pose);
  });
  if (trajectory.empty()) throw InputError(path + ": no poses in trajectory file");
  return trajectory;
}

Trajectory ReadTumGroundTruth(const std::string& path) {
  TrajectoryReadOptions options;
  options.keep_last_of_duplicate_timestamps = true;
  return ReadTumTrajectory(path, options);
}

std::string FormatTumPoseLine(const StampedPose& pose) {
  const Eigen::Vector3d& t = pose.world_from_cam.translation;
  const Eigen::Quaterniond& q = pose.world_from_cam.rotation;
  char buf[256];
  const int length =
      std::snprintf(buf, sizeof(buf), "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f", pose.timestamp_s,
                    t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  // Values beyond ~1e200 would not fit: a cut line is a file no reader can take back.
  if (length < 0 || length >= static_cast<int>(sizeof(buf)))
    throw InputError("a pose too large to write in TUM format (timestamp " +
                     std::to_string(pose.timestamp_s) + " s, |t| = " + std::to_string(t.norm()) +
                     " m)");
  return buf;
}

void WriteTumTrajectory(const std::string& path, const Trajectory& trajectory) {
  AtomicFile file(path);
  file.stream() << "# timestamp tx ty tz qx qy qz qw (world_from_cam)\n";
  for (const StampedPose& pose : trajectory) file.stream() << FormatTumPoseLine(pose) << '\n';
  file.Commit();
}

}  // namespace dynorb
