#include "orbis/version.hpp"

namespace orbis {
const char* versionString() { return "0.1.0"; }
}  // namespace orbis
