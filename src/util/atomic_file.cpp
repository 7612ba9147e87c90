#include "orbis/util/atomic_file.hpp"

#include <fstream>

#include "orbis/util/error.hpp"

namespace orbis {

void writeFileAtomically(const std::filesystem::path& path, std::span<const char> bytes) {
  const std::filesystem::path temporary = path.string() + ".tmp";
  std::error_code ignored;
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw fileError(temporary.string(), "cannot open for writing");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      out.close();
      std::filesystem::remove(temporary, ignored);
      throw fileError(temporary.string(), "write failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary, ignored);
    throw fileError(path.string(), "cannot move the written file into place: " + ec.message());
  }
}

}  // namespace orbis
