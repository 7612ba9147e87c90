// One libFuzzer target per parser harness: compiled once per harness with
// ORBIS_FUZZ_HARNESS="<name>" (tests/fuzz/CMakeLists.txt). A harness may refuse an input with
// orbis::Error; anything else escaping it aborts, which libFuzzer reports as a crash.
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "../harnesses.hpp"
#include "orbis/util/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const orbis::fuzz::Harness* harness = [] {
    const orbis::fuzz::Harness* h = orbis::fuzz::findHarness(ORBIS_FUZZ_HARNESS);
    if (!h) {
      std::fprintf(stderr, "no fuzz harness named %s\n", ORBIS_FUZZ_HARNESS);
      std::abort();
    }
    return h;
  }();
  try {
    harness->run(data, size);
  } catch (const orbis::Error&) {
  }
  return 0;
}
