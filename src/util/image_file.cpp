#include "orbis/util/image_file.hpp"

#include <opencv2/imgcodecs.hpp>

#include "orbis/util/error.hpp"

namespace orbis {

void writeImageFile(const std::filesystem::path& file, const cv::Mat& image) {
  bool ok = false;
  try {
    ok = cv::imwrite(file.string(), image);
  } catch (const cv::Exception& e) {
    throw fileError(file.string(), std::string("cannot write image: ") + e.what());
  }
  if (!ok) throw fileError(file.string(), "cannot write image");
}

}  // namespace orbis
