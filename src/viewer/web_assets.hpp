// src/viewer/web_assets.hpp — the page's files, compiled into the library at build time.
//
// Contract: webAsset(path) returns the file served at `path` ("/", "/viewer.js",
// "/three.min.js", ...) with its content type, or null when there is none. The bytes come from
// src/viewer/web/ and Debian's libjs-three, embedded by cmake/EmbedWebAssets.cmake.
#pragma once

#include <cstddef>
#include <string_view>

namespace orbis::viewer_detail {

struct WebAsset {
  std::string_view path, contentType;
  const unsigned char* data;
  std::size_t size;
};

const WebAsset* webAsset(std::string_view path);

}  // namespace orbis::viewer_detail
