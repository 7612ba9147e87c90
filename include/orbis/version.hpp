// orbis/version.hpp — library version, for programs and consumers that report it.
#pragma once

namespace orbis {
// The library's version, "MAJOR.MINOR.PATCH".
const char* versionString();
}
