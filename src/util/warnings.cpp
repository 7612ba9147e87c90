// Folding repeated warnings; see orbis/util/warnings.hpp.
#include "orbis/util/warnings.hpp"

#include <cctype>
#include <unordered_map>

namespace orbis {
namespace {

std::string digitsFolded(const std::string& message) {
  std::string pattern;
  pattern.reserve(message.size());
  for (std::size_t i = 0; i < message.size(); ++i) {
    const bool digit = std::isdigit(static_cast<unsigned char>(message[i])) != 0;
    if (!digit) {
      pattern += message[i];
    } else if (i == 0 || !std::isdigit(static_cast<unsigned char>(message[i - 1]))) {
      pattern += '#';
    }
  }
  return pattern;
}

}  // namespace

std::vector<WarningKind> foldWarnings(const std::vector<std::string>& warnings, std::size_t shownPerKind) {
  std::vector<WarningKind> kinds;
  std::unordered_map<std::string, std::size_t> kindOf;
  for (const std::string& message : warnings) {
    std::string pattern = digitsFolded(message);
    const auto [it, isNew] = kindOf.try_emplace(pattern, kinds.size());
    if (isNew) kinds.push_back({std::move(pattern), {}, 0});
    WarningKind& kind = kinds[it->second];
    if (kind.shown.size() < shownPerKind) kind.shown.push_back(message);
    ++kind.count;
  }
  return kinds;
}

std::vector<std::string> readableWarnings(const std::vector<WarningKind>& kinds) {
  std::vector<std::string> lines;
  for (const WarningKind& kind : kinds) {
    lines.insert(lines.end(), kind.shown.begin(), kind.shown.end());
    if (kind.count > kind.shown.size())
      lines.push_back("... (" + std::to_string(kind.count - kind.shown.size()) + " more like this)");
  }
  return lines;
}

}  // namespace orbis
