#include "orbis/version.hpp"

namespace orbis {
// ORBIS_VERSION is the project() version in CMakeLists.txt.
const char* versionString() { return ORBIS_VERSION; }
}  // namespace orbis
