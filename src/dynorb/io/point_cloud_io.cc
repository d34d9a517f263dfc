#include "dynorb/io/point_cloud_io.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>

#include "dynorb/core/error.h"
#include "dynorb/io/atomic_file.h"

namespace dynorb {
namespace {

bool ValidName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

// Little-endian IEEE-754 bytes of a float, independent of the host's byte order.
void AppendFloat(float value, std::string* out) {
  uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((bits >> (8 * i)) & 0xFF));
}

float ReadFloat(const unsigned char* bytes) {
  uint32_t bits = 0;
  for (int i = 0; i < 4; ++i) bits |= static_cast<uint32_t>(bytes[i]) << (8 * i);
  float value = 0.f;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

}  // namespace

void WritePlyPointCloud(const std::string& path, const PointCloud& cloud) {
  const size_t n = cloud.points.size();
  if (cloud.rgb.size() != n) {
    throw InputError(path + ": " + std::to_string(n) + " points but " +
                     std::to_string(cloud.rgb.size()) + " colours");
  }
  std::set<std::string> names = {"x", "y", "z", "red", "green", "blue"};
  for (const auto& [name, values] : cloud.flags) {
    if (!ValidName(name) || !names.insert(name).second)
      throw InputError(path + ": bad or repeated point property name '" + name + "'");
    if (values.size() != n) {
      throw InputError(path + ": property '" + name + "' has " + std::to_string(values.size()) +
                       " values for " + std::to_string(n) + " points");
    }
  }
  std::string data = "ply\nformat binary_little_endian 1.0\ncomment written by dynorb\n";
  data += "element vertex " + std::to_string(n) + "\n";
  data += "property float x\nproperty float y\nproperty float z\n";
  data += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  for (const auto& flag : cloud.flags) data += "property uchar " + flag.first + "\n";
  data += "end_header\n";
  data.reserve(data.size() + n * (15 + cloud.flags.size()));
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) AppendFloat(cloud.points[i][k], &data);
    for (int k = 0; k < 3; ++k) data.push_back(static_cast<char>(cloud.rgb[i][k]));
    for (const auto& flag : cloud.flags) data.push_back(static_cast<char>(flag.second[i]));
  }
  WriteFileAtomically(path, data);
}

PointCloud ReadPlyPointCloud(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string end_marker = "\nend_header\n";
  const size_t end = bytes.find(end_marker);
  if (bytes.compare(0, 4, "ply\n") != 0 || end == std::string::npos)
    throw InputError(path + ": not a PLY file (no 'ply' line or no end_header)");
  std::istringstream header(bytes.substr(0, end + 1));
  std::string line;
  std::getline(header, line);  // "ply"
  long long count = -1;
  bool binary_le = false;
  std::vector<std::string> properties;
  auto refuse = [&path](const std::string& what) {
    throw InputError(path + ": " + what +
                     " (dynorb reads its own point clouds: binary_little_endian 1.0, one "
                     "'element vertex N', float x y z, uchar red green blue, more uchars)");
  };
  while (std::getline(header, line)) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "format") {
      std::string format, version;
      words >> format >> version;
      binary_le = format == "binary_little_endian" && version == "1.0";
    } else if (keyword == "element") {
      std::string name;
      long long n = -1;
      words >> name >> n;
      if (name != "vertex" || !words || n < 0 || count >= 0 || !properties.empty())
        refuse("unexpected '" + line + "'");
      count = n;
    } else if (keyword == "property") {
      std::string type, name;
      words >> type >> name;
      const bool position = properties.size() < 3;
      if (count < 0 || type != (position ? "float" : "uchar") || !ValidName(name) ||
          std::find(properties.begin(), properties.end(), name) != properties.end()) {
        refuse("unexpected '" + line + "'");
      }
      properties.push_back(name);
    } else if (keyword != "comment" && !keyword.empty()) {
      refuse("unexpected header line '" + line + "'");
    }
  }
  const std::vector<std::string> fixed = {"x", "y", "z", "red", "green", "blue"};
  if (!binary_le || count < 0 || properties.size() < fixed.size() ||
      !std::equal(fixed.begin(), fixed.end(), properties.begin())) {
    refuse("not a dynorb point cloud");
  }
  const size_t stride = 12 + (properties.size() - 3);
  const size_t body = end + end_marker.size();
  const size_t available = bytes.size() - body;
  // Divided, not multiplied: a huge vertex count must not wrap around.
  if (available % stride != 0 || available / stride != static_cast<unsigned long long>(count)) {
    throw InputError(path + ": " + std::to_string(available) + " data bytes do not hold " +
                     std::to_string(count) + " points of " + std::to_string(stride) + " bytes");
  }
  PointCloud cloud;
  for (size_t p = 6; p < properties.size(); ++p)
    cloud.flags.emplace_back(properties[p], std::vector<uint8_t>());
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data() + body);
  for (long long i = 0; i < count; ++i, data += stride) {
    cloud.points.emplace_back(ReadFloat(data), ReadFloat(data + 4), ReadFloat(data + 8));
    cloud.rgb.emplace_back(data[12], data[13], data[14]);
    for (size_t f = 0; f < cloud.flags.size(); ++f) cloud.flags[f].second.push_back(data[15 + f]);
  }
  return cloud;
}

}  // namespace dynorb
