// orbis/version.hpp — library version, for programs and consumers that report it.
#pragma once

namespace orbis {
const char* versionString();
}
