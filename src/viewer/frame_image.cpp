#include "frame_image.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace orbis::viewer_detail {
namespace {

std::string base64(const std::vector<unsigned char>& bytes) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = bytes[i] << 16 | bytes[i + 1] << 8 | bytes[i + 2];
    out += kDigits[v >> 18];
    out += kDigits[v >> 12 & 63];
    out += kDigits[v >> 6 & 63];
    out += kDigits[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const unsigned v = bytes[i] << 16 | (two ? bytes[i + 1] << 8 : 0);
    out += kDigits[v >> 18];
    out += kDigits[v >> 12 & 63];
    out += two ? kDigits[v >> 6 & 63] : '=';
    out += '=';
  }
  return out;
}

}  // namespace

std::string jpegBase64(const cv::Mat& image, int maxWidth, int quality) {
  if (image.empty() || maxWidth <= 0 || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    return "";
  cv::Mat scaled = image;
  if (image.cols > maxWidth) {
    const int height = std::max(1, static_cast<int>(std::lround(image.rows * double(maxWidth) / image.cols)));
    // INTER_AREA: averages the pixels a downscale drops, so the picture does not alias.
    cv::resize(image, scaled, cv::Size(maxWidth, height), 0, 0, cv::INTER_AREA);
  }
  std::vector<unsigned char> jpeg;
  if (!cv::imencode(".jpg", scaled, jpeg, {cv::IMWRITE_JPEG_QUALITY, quality})) return "";
  return base64(jpeg);
}

}  // namespace orbis::viewer_detail
