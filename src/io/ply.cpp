#include "orbis/io/ply.hpp"

#include <fstream>

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

}  // namespace orbis
