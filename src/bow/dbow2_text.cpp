#include "orbis/bow/dbow2_text.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace orbis::bow::detail {

std::string readWholeFile(const std::filesystem::path& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw fileError(path.string(), "cannot open: " + std::string(std::strerror(errno)));
  std::string text;
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec) text.resize(size);
  const std::size_t got = ec ? 0 : std::fread(text.data(), 1, text.size(), f);
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (ec || failed || got != text.size()) throw fileError(path.string(), "read failed");
  return text;
}

}  // namespace orbis::bow::detail
