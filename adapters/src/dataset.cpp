// The dataset factory, name parsing and the helpers shared by the readers.
#include "orbis/adapters/dataset.hpp"

#include <opencv2/imgcodecs.hpp>

#include "dataset_common.hpp"
#include "orbis/util/enum_names.hpp"
#include "orbis/util/error.hpp"

namespace orbis {

namespace {
constexpr EnumName<DatasetKind> kDatasetKindNames[] = {
    {DatasetKind::TumRgbd, "tum"}, {DatasetKind::Euroc, "euroc"}, {DatasetKind::Kitti, "kitti"},
    {DatasetKind::KittiRaw, "kitti-raw"}};
}  // namespace

DatasetKind parseDatasetKind(std::string_view name, const std::string& source) {
  return parseEnumName(kDatasetKindNames, name, "dataset kind", source);
}

std::string_view toString(DatasetKind kind) { return enumName(kDatasetKindNames, kind); }

std::optional<DatasetKind> detectDatasetKind(const std::filesystem::path& root) {
  namespace fs = std::filesystem;
  if (fs::exists(root / "rgb.txt")) return DatasetKind::TumRgbd;
  if (fs::exists(root / "mav0") || fs::exists(root / "cam0" / "data.csv")) return DatasetKind::Euroc;
  if (fs::exists(root / "sequences") || fs::exists(root / "times.txt")) return DatasetKind::Kitti;
  if (fs::exists(root / "image_00" / "timestamps.txt")) return DatasetKind::KittiRaw;
  return std::nullopt;
}

std::unique_ptr<DatasetReader> openDataset(DatasetKind kind, const std::filesystem::path& root,
                                           const DatasetOptions& options) {
  switch (kind) {
    case DatasetKind::TumRgbd:
      return openTumRgbd(root, options);
    case DatasetKind::Euroc:
      return openEuroc(root, options);
    case DatasetKind::Kitti:
      return openKitti(root, options);
    case DatasetKind::KittiRaw:
      return openKittiRaw(root, options);
  }
  throw Error(root.string(), "", "unknown dataset kind");
}

namespace adapters_detail {

void requireExists(const std::filesystem::path& path, const std::string& what) {
  if (!std::filesystem::exists(path)) throw fileError(path.string(), what + " does not exist");
}

// A listed name the file system refuses outright (a component longer than NAME_MAX: found by
// fuzzing the TUM list) names no file: report it missing, never let filesystem_error escape.
namespace {
bool listedFileExists(const std::filesystem::path& file) {
  std::error_code error;
  return std::filesystem::exists(file, error);
}
}  // namespace

std::vector<ListedImage> readImageList(const std::filesystem::path& listFile,
                                       const std::filesystem::path& imageDir, TimeUnit unit,
                                       bool requireImages, std::vector<std::string>& warnings) {
  std::vector<ListedImage> rows;
  forEachTextRow(listFile, [&](const TextRow& row) {
    if (row.fields.size() != 2)
      throw lineError(listFile.string(), row.line,
                      "expected 2 fields (timestamp, file name), found " + std::to_string(row.fields.size()));
    ListedImage image;
    image.t = unit == TimeUnit::Seconds
                  ? parseDouble(row.fields[0], listFile, row.line)
                  : static_cast<double>(parseInteger(row.fields[0], listFile, row.line)) * 1e-9;
    image.file = imageDir / std::string(row.fields[1]);
    image.listFile = listFile;
    image.line = row.line;
    image.exists = listedFileExists(image.file);
    if (requireImages && !image.exists)
      throw lineError(listFile.string(), row.line, "image " + image.file.string() + " does not exist");
    rows.push_back(std::move(image));
  });
  std::vector<double> times;
  std::vector<std::size_t> lines;
  for (const ListedImage& image : rows) {
    times.push_back(image.t);
    lines.push_back(image.line);
  }
  const TimeOrder order = putInTimeOrder(times, lines);
  for (std::string& w : order.warnings(listFile)) warnings.push_back(std::move(w));
  std::vector<ListedImage> images;
  images.reserve(order.keep.size());
  for (const std::size_t i : order.keep) images.push_back(std::move(rows[i]));
  return images;
}

cv::Mat loadImage(const std::filesystem::path& file, int imreadFlags, const std::filesystem::path& listFile,
                  std::size_t line) {
  cv::Mat image;
  try {
    image = cv::imread(file.string(), imreadFlags);
  } catch (const cv::Exception&) {
    image.release();
  }
  if (image.empty()) {
    const std::string what = listedFileExists(file)
                                 ? "cannot read the image " + file.string() + " (truncated or not an image)"
                                 : "image " + file.string() + " does not exist";
    if (!listFile.empty()) throw lineError(listFile.string(), line, what);
    throw fileError(file.string(), "cannot read the image (missing, truncated or not an image)");
  }
  return image;
}

cv::Mat loadImage(const ListedImage& image, int imreadFlags) {
  return loadImage(image.file, imreadFlags, image.listFile, image.line);
}

void reportMissing(std::vector<std::string>& warnings, bool strict, const std::filesystem::path& source,
                   std::size_t line, const std::string& what) {
  if (strict) {
    if (line > 0) throw lineError(source.string(), line, what);
    throw fileError(source.string(), what);
  }
  warnings.push_back(source.string() + (line > 0 ? ", line " + std::to_string(line) : "") + ": " + what);
}

std::vector<double> timesOf(const std::vector<ListedImage>& images) {
  std::vector<double> times;
  times.reserve(images.size());
  for (const ListedImage& image : images) times.push_back(image.t);
  return times;
}

PairedImages::PairedImages(const std::vector<ListedImage>& primary, std::vector<ListedImage> partners,
                           double maxDt, std::string partnerName)
    : partners_(std::move(partners)),
      partnerOf_(primary.size(), kNone),
      maxDt_(maxDt),
      partnerName_(std::move(partnerName)) {
  for (const auto& [p, q] : associateTimestamps(timesOf(primary), timesOf(partners_), maxDt))
    partnerOf_[p] = q;
}

const ListedImage* PairedImages::find(const std::vector<ListedImage>& primary, std::size_t index,
                                      std::vector<std::string>& warnings, bool strict) const {
  const ListedImage& image = primary[index];
  if (partnerOf_[index] == kNone) {
    reportMissing(warnings, strict, image.listFile, image.line,
                  "no " + partnerName_ + " within " + std::to_string(maxDt_) + " s of " +
                      image.file.filename().string());
    return nullptr;
  }
  const ListedImage& partner = partners_[partnerOf_[index]];
  if (!partner.exists) {
    reportMissing(warnings, strict, partner.listFile, partner.line,
                  partnerName_ + " " + partner.file.string() + " does not exist");
    return nullptr;
  }
  return &partner;
}

std::size_t PairedImages::pairedOnDisk() const {
  std::size_t count = 0;
  for (const std::size_t partner : partnerOf_) count += partner != kNone && partners_[partner].exists;
  return count;
}

void PairedImages::requireAll(const std::vector<ListedImage>& primary) const {
  std::vector<std::string> unused;
  for (std::size_t i = 0; i < primary.size(); ++i) find(primary, i, unused, true);
}

}  // namespace adapters_detail
}  // namespace orbis
