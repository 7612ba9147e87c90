// orbis/util/error.hpp — the one exception type thrown at the library's boundary.
//
// Contract: every failure caused by outside input (files, settings, command-line arguments)
// is reported as orbis::Error, whose message names the source (file path), the location
// (line number or settings key, when known) and what was expected. Hot loops never throw;
// a bad frame becomes a tracking state instead.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>

namespace orbis {

// The one exception orbis throws for bad input: what() reads "source: where: what", naming the
// file, device or argument, and the key or line.
class Error : public std::runtime_error {
 public:
  // source: file path or other origin ("settings", "argument --max-dt"); where: "line 12",
  // "key Camera.fx" or empty; what: the problem, phrased as what was expected or found.
  Error(std::string source, std::string where, const std::string& what)
      : std::runtime_error(compose(source, where, what)),
        source_(std::move(source)),
        where_(std::move(where)) {}

  // @{
  // The origin (file, device, argument) and the place in it (key or line; may be empty).
  const std::string& source() const noexcept { return source_; }
  const std::string& where() const noexcept { return where_; }
  // @}

 private:
  static std::string compose(const std::string& source, const std::string& where,
                             const std::string& what) {
    std::string msg = source;
    if (!where.empty()) msg += ", " + where;
    msg += ": " + what;
    return msg;
  }
  std::string source_;
  std::string where_;
};

// An error about a whole file.
inline Error fileError(const std::string& path, const std::string& what) { return {path, "", what}; }
// An error at a line of a file.
inline Error lineError(const std::string& path, std::size_t line, const std::string& what) {
  return {path, "line " + std::to_string(line), what};
}
// An error about a key of a file.
inline Error keyError(const std::string& path, const std::string& key, const std::string& what) {
  return {path, "key " + key, what};
}

}  // namespace orbis
