// orbis/util/atomic_file.hpp — writes a whole file so that readers see the old or the new
// content, never half of one.
//
// Contract: writeFileAtomically writes `bytes` to `path`.tmp, flushes, checks the stream and
// renames it over `path`. On any failure it throws orbis::Error naming the file, removes the
// temporary, and leaves an existing `path` untouched (a failed map save keeps the previous map).
#pragma once

#include <filesystem>
#include <span>

namespace orbis {

// Writes bytes to path through a temporary file in the same folder and a rename, so a reader never
// sees half a file; throws orbis::Error naming the path.
void writeFileAtomically(const std::filesystem::path& path, std::span<const char> bytes);

}  // namespace orbis
