// Private helpers shared by the dataset readers: image lists, image loading, missing-data reports.
#pragma once

#include <cstddef>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "orbis/adapters/dataset.hpp"

namespace orbis::adapters_detail {

// One image named by a list file ("t filename" rows: TUM lists in seconds, EuRoC data.csv in
// nanoseconds), remembering where it was listed so errors can name the line.
struct ListedImage {
  double t = 0.0;
  std::filesystem::path file;
  std::filesystem::path listFile;
  std::size_t line = 0;
  bool exists = false;
};

enum class TimeUnit { Seconds, Nanoseconds };

// Reads the list and checks every row (two fields, a number) and whether each image exists.
// When requireImages, a missing image throws naming list and line. Rows out of time order are
// sorted, and of rows with equal timestamps the first is kept; `warnings` gets one line per
// kind of repair.
std::vector<ListedImage> readImageList(const std::filesystem::path& listFile,
                                       const std::filesystem::path& imageDir, TimeUnit unit,
                                       bool requireImages, std::vector<std::string>& warnings);

// Throws orbis::Error naming the file (and where it was listed, if known) when unreadable.
cv::Mat loadImage(const std::filesystem::path& file, int imreadFlags,
                  const std::filesystem::path& listFile = {}, std::size_t line = 0);
cv::Mat loadImage(const ListedImage& image, int imreadFlags);

// A right image or depth map that is not there: a warning on the frame, or with
// options.strict an orbis::Error at once.
void reportMissing(std::vector<std::string>& warnings, bool strict, const std::filesystem::path& source,
                   std::size_t line, const std::string& what);

// Throws orbis::Error naming the path when it does not exist.
void requireExists(const std::filesystem::path& path, const std::string& what);

std::vector<double> timesOf(const std::vector<ListedImage>& images);

// A second image stream (depth maps, right images) paired one-to-one with a primary stream by
// nearest timestamps within maxDt.
class PairedImages {
 public:
  PairedImages() = default;
  PairedImages(const std::vector<ListedImage>& primary, std::vector<ListedImage> partners, double maxDt,
               std::string partnerName);
  // The partner of primary[index] when it is on disk; otherwise reports why it is missing
  // (reportMissing) and returns nullptr.
  const ListedImage* find(const std::vector<ListedImage>& primary, std::size_t index,
                          std::vector<std::string>& warnings, bool strict) const;
  // Throws orbis::Error for the first primary image without a partner on disk.
  void requireAll(const std::vector<ListedImage>& primary) const;
  // How many primary images have a partner on disk; how many partners were listed at all.
  std::size_t pairedOnDisk() const;
  std::size_t listed() const { return partners_.size(); }

 private:
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::vector<ListedImage> partners_;
  std::vector<std::size_t> partnerOf_;  // index into partners_ per primary image, or kNone
  double maxDt_ = 0.0;
  std::string partnerName_;
};

}  // namespace orbis::adapters_detail
