#include "orbis/io/ply.hpp"

#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "orbis/util/error.hpp"

namespace orbis {

void writePly(const std::filesystem::path& path, const std::vector<Eigen::Vector3f>& points,
              const std::vector<std::array<std::uint8_t, 3>>& colours) {
  const bool withColour = !colours.empty();
  if (withColour && colours.size() != points.size())
    throw fileError(path.string(), "PLY colours (" + std::to_string(colours.size()) + ") do not match points (" +
                                       std::to_string(points.size()) + ")");
  std::ofstream out(path, std::ios::binary);
  if (!out) throw fileError(path.string(), "cannot open for writing");
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << points.size()
      << "\nproperty float x\nproperty float y\nproperty float z\n";
  if (withColour) out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out << "end_header\n";
  for (std::size_t i = 0; i < points.size(); ++i) {
    out.write(reinterpret_cast<const char*>(points[i].data()), 3 * sizeof(float));
    if (withColour) out.write(reinterpret_cast<const char*>(colours[i].data()), 3);
  }
  if (!out) throw fileError(path.string(), "write failed (disk full?)");
}

std::vector<Eigen::Vector3f> readPly(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw fileError(path.string(), "cannot open for reading");
  std::string line, word;
  std::size_t count = 0, stride = 0;
  bool binary = false;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream fields(line);
    fields >> word;
    if (word == "format") binary = line.find("binary_little_endian") != std::string::npos;
    else if (word == "element" && line.find("vertex") != std::string::npos) fields >> word >> count;
    else if (word == "property") stride += line.find("uchar") != std::string::npos ? 1 : 4;
  }
  if (!binary || stride < 12 || line != "end_header")
    throw fileError(path.string(), "not a binary little-endian PLY with float x, y, z first");
  std::vector<Eigen::Vector3f> points(count);
  std::vector<char> record(stride);
  for (Eigen::Vector3f& p : points) {
    if (!in.read(record.data(), static_cast<std::streamsize>(stride))) throw fileError(path.string(), "truncated PLY");
    std::memcpy(p.data(), record.data(), 3 * sizeof(float));
  }
  return points;
}

}  // namespace orbis
