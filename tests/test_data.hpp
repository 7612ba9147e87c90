// tests/test_data.hpp — where the tests find real benchmark data, and how they skip without it.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace orbis::test {

// ORBIS_DATA wins; otherwise ../shared/datasets beside the source tree.
inline std::filesystem::path dataRoot() {
  if (const char* env = std::getenv("ORBIS_DATA"); env && *env) return env;
  return ORBIS_DEFAULT_DATA_DIR;
}

inline std::optional<std::filesystem::path> dataset(const std::string& name) {
  const auto p = dataRoot() / name;
  if (std::filesystem::exists(p)) return p;
  return std::nullopt;
}

inline std::filesystem::path sourceDir() { return ORBIS_SOURCE_DIR; }

// A file's whole content, byte for byte (empty when it cannot be read): outputs compared whole.
inline std::string fileBytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

}  // namespace orbis::test

// Skips the current test when the named dataset folder is absent (a user's fresh machine).
#define ORBIS_REQUIRE_DATASET(var, name)                                              \
  const auto var##_opt = ::orbis::test::dataset(name);                                \
  if (!var##_opt) GTEST_SKIP() << "dataset " << name << " not found under " << ::orbis::test::dataRoot(); \
  const std::filesystem::path var = *var##_opt
