#include "orbis/util/atomic_file.hpp"

#include <fstream>

#include "orbis/util/error.hpp"

namespace orbis {

void writeFileAtomically(const std::filesystem::path& path, std::span<const char> bytes) {
  const std::filesystem::path temporary = path.string() + ".tmp";
  std::error_code ignored;
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    // Named after the file the user asked for; the temporary beside it is ours.
    if (!out)
      throw fileError(path.string(), "cannot write (the temporary " + temporary.filename().string() +
                                         " beside it cannot be created: missing folder or no permission)");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      out.close();
      std::filesystem::remove(temporary, ignored);
      throw fileError(path.string(), "write failed (disk full?); the file was left as it was");
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
