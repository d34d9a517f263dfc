// Coloured point clouds as PLY files (binary little-endian), the format MeshLab, CloudCompare,
// Open3D and Blender open: `dynorb run --save-map` writes the map's landmarks this way.
//
// Vertex properties, in this order: float x, y, z (metres, world frame); uchar red, green, blue;
// then one uchar property per entry of `flags` (named by the caller, e.g. "dynamic_object_id").
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

namespace dynorb {

struct PointCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<cv::Vec3b> rgb;  // red, green, blue per point (same length as points)
  // Extra per-point byte properties: name ([a-z0-9_]+) and one value per point.
  std::vector<std::pair<std::string, std::vector<uint8_t>>> flags;
};

// Writes atomically (nothing is left behind on failure). Throws InputError for mismatched
// lengths, a bad property name, or an unwritable path.
void WritePlyPointCloud(const std::string& path, const PointCloud& cloud);

// Reads a file written by WritePlyPointCloud (binary little-endian, the properties above).
// Throws InputError naming the file for anything else (ASCII PLY, other properties, truncated).
PointCloud ReadPlyPointCloud(const std::string& path);

}  // namespace dynorb
