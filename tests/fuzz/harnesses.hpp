// tests/fuzz/harnesses.hpp — every file parser of orbis, fed arbitrary bytes as a file's content.
//
// Contract: a harness writes the bytes into a scratch folder of its own process, with whatever
// companion files the parser needs (valid ones), and calls the parser. It returns normally or
// throws orbis::Error (a refused input); a crash, a sanitizer report, a hang or any other
// exception is a bug. The same harnesses serve the libFuzzer targets (targets/fuzz_target.cpp,
// clang, ORBIS_BUILD_FUZZERS) and the corpus replay in the ordinary test suite.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

namespace orbis::fuzz {

struct Harness {
  std::string_view name;  // also the corpus folder, tests/fuzz/corpus/<name>/
  void (*run)(const std::uint8_t* data, std::size_t size);
};

const std::vector<Harness>& harnesses();
const Harness* findHarness(std::string_view name);  // nullptr when unknown

}  // namespace orbis::fuzz
