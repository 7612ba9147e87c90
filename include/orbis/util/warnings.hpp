// orbis/util/warnings.hpp — the same warning said many times, folded for a person to read.
//
// Contract: two warnings are alike when they differ only in their digits (frame indices, line
// numbers, timestamps, numbered image names). foldWarnings groups alike warnings into kinds, in
// the order of each kind's first warning, keeping the first `shownPerKind` messages of a kind
// verbatim and counting all of them. Pure functions, no I/O.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace orbis {

// Warnings that differ only in their numbers, folded into one kind.
struct WarningKind {
  std::string pattern;             // the first message with every run of digits replaced by '#'
  std::vector<std::string> shown;  // its first messages, verbatim
  std::size_t count = 0;           // every message of this kind, shown or not
};

// Groups warnings by kind, keeping the first shownPerKind messages of each verbatim.
std::vector<WarningKind> foldWarnings(const std::vector<std::string>& warnings, std::size_t shownPerKind = 3);

// The lines to print: each kind's shown messages, then "... (N more like this)" when it had more.
std::vector<std::string> readableWarnings(const std::vector<WarningKind>& kinds);

}  // namespace orbis
