// orbis/util/enum_names.hpp — the names of an enum's values, read and written from one table.
//
// Contract: a table is a constant array of {value, name} rows; a value may have several names
// (spellings a user may type), and its first row gives the name written back. findEnumName
// returns the value a text names (exact match, or ignoring ASCII letter case when asked) or
// nothing; parseEnumName throws orbis::Error(source, where, `unknown <what> "text" (expected
// a, b or c)`) instead, listing every name in table order; enumName returns a value's first name,
// or "?" for a value the table lacks. Used at the boundary only (settings keys, command-line
// arguments, file headers), so a linear search is the right cost.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "orbis/util/error.hpp"

namespace orbis {

// One row of an enum's name table: a value and its name.
template <class Enum>
struct EnumName {
  // @{
  // The value and the name it is written as.
  Enum value;
  std::string_view name;
  // @}
};

// Whether names compare exactly or ignoring ASCII letter case.
enum class LetterCase { Exact, Ignored };

namespace enum_names_detail {
constexpr char asciiLower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }
constexpr bool sameName(std::string_view a, std::string_view b, LetterCase letterCase) {
  if (letterCase == LetterCase::Exact) return a == b;
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (asciiLower(a[i]) != asciiLower(b[i])) return false;
  }
  return true;
}
}  // namespace enum_names_detail

// The value whose name is text, or nothing.
template <class Enum, std::size_t N>
constexpr std::optional<Enum> findEnumName(const EnumName<Enum> (&table)[N], std::string_view text,
                                           LetterCase letterCase = LetterCase::Exact) {
  for (const EnumName<Enum>& row : table) {
    if (enum_names_detail::sameName(row.name, text, letterCase)) return row.value;
  }
  return std::nullopt;
}

// what: the kind of name ("sensor", "dataset kind"); source and where: as orbis::Error's.
template <class Enum, std::size_t N>
Enum parseEnumName(const EnumName<Enum> (&table)[N], std::string_view text, std::string_view what,
                   const std::string& source, const std::string& where = "",
                   LetterCase letterCase = LetterCase::Exact) {
  if (const auto value = findEnumName(table, text, letterCase)) return *value;
  std::string expected;
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) expected += i + 1 == N ? " or " : ", ";
    expected += table[i].name;
  }
  if (letterCase == LetterCase::Ignored) expected += "; any letter case";
  throw Error(source, where,
              "unknown " + std::string(what) + " \"" + std::string(text) + "\" (expected " + expected + ")");
}

// The name of value in table (empty when it has none).
template <class Enum, std::size_t N>
constexpr std::string_view enumName(const EnumName<Enum> (&table)[N], Enum value) {
  for (const EnumName<Enum>& row : table) {
    if (row.value == value) return row.name;
  }
  return "?";
}

}  // namespace orbis
