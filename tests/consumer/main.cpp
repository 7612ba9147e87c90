// Uses the installed orbis package: prints the version. Extended as components land.
#include <cstdio>

#include "orbis/version.hpp"

int main() {
  std::printf("orbis %s found through find_package\n", orbis::versionString());
  return 0;
}
