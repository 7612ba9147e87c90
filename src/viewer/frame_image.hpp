// src/viewer/frame_image.hpp — the current camera image as the page receives it.
//
// Contract: jpegBase64(image, maxWidth, quality) scales an 8-bit grey or BGR image down to at
// most maxWidth pixels wide (aspect kept; never up), encodes it as JPEG at `quality` (0-100) and
// returns the bytes in base64 (for a data: URL in a JSON message); "" for an empty or
// unsupported image or maxWidth <= 0. Runs on the viewer's publisher thread, never on tracking's.
#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace orbis::viewer_detail {

std::string jpegBase64(const cv::Mat& image, int maxWidth, int quality);

}  // namespace orbis::viewer_detail
