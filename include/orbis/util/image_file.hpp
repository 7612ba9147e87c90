// orbis/util/image_file.hpp — writing an image file with an orbis error on failure.
//
// Contract: writeImageFile writes image with OpenCV (the format from the file's extension) and
// throws orbis::Error naming the file when OpenCV refuses or fails; it creates no folders.
#pragma once

#include <filesystem>

#include <opencv2/core.hpp>

namespace orbis {

// Writes image to file (PNG, JPEG, ... by extension); throws orbis::Error naming the file on failure.
void writeImageFile(const std::filesystem::path& file, const cv::Mat& image);

}  // namespace orbis
