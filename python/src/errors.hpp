// python/src/errors.hpp — orbis errors as Python exceptions.
//
// Contract: bindErrors (bindings.hpp) creates orbis.Error, a RuntimeError subclass that every
// orbis::Error thrown by the library becomes, carrying its message and, as attributes, its
// `source` (file or origin) and `where` (line or settings key, may be empty); and
// orbis.MissingFileError, a subclass of both FileNotFoundError and orbis.Error, raised by
// requireFile before a loader is handed a path that does not exist.
#pragma once

#include <filesystem>

namespace orbis::python {

// Raises orbis.MissingFileError (through pybind11::error_already_set) when `file` does not exist.
void requireFile(const std::filesystem::path& file);

}  // namespace orbis::python
