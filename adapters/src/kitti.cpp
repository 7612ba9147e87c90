// KITTI odometry reader: sequences/NN/{image_0, image_1 (optional), times.txt, calib.txt} and
// poses/NN.txt (optional: sequences 11-21 have no public ground truth).
#include "kitti_common.hpp"
#include "orbis/util/error.hpp"

namespace orbis {
namespace {

using namespace adapters_detail;
namespace fs = std::filesystem;

struct KittiLayout {
  fs::path sequenceDir;  // holds times.txt, calib.txt, image_0
  fs::path posesFile;    // may not exist
};

// root may be the dataset root (with sequences/ and poses/) or a sequence folder itself.
KittiLayout locate(const fs::path& root, const std::string& sequence) {
  if (fs::exists(root / "times.txt")) {
    fs::path dir = fs::absolute(root).lexically_normal();
    if (dir.filename().empty()) dir = dir.parent_path();  // a trailing slash
    return {root, dir.parent_path().parent_path() / "poses" / (dir.filename().string() + ".txt")};
  }
  const fs::path sequences = root / "sequences";
  requireExists(sequences, "the KITTI sequences folder");
  std::string chosen = sequence;
  if (chosen.empty()) {
    std::vector<std::string> found;
    for (const auto& entry : fs::directory_iterator(sequences))
      if (entry.is_directory()) found.push_back(entry.path().filename().string());
    if (found.size() != 1)
      throw fileError(sequences.string(), "holds " + std::to_string(found.size()) +
                                              " sequences; name one (DatasetOptions::kittiSequence)");
    chosen = found.front();
  }
  return {sequences / chosen, root / "poses" / (chosen + ".txt")};
}

// calib.txt rows "P0: p00 ... p23" (P2, P3 and the velodyne's Tr are not needed).
class KittiReader final : public KittiImagesReader {
 public:
  KittiReader(const fs::path& root, const DatasetOptions& options) {
    const KittiLayout layout = locate(root, options.kittiSequence);
    const fs::path timesFile = layout.sequenceDir / "times.txt";
    requireExists(timesFile, "the KITTI times file");
    openImages(root,
               {timesFile, readTimestamps(timesFile), layout.sequenceDir / "image_0", layout.sequenceDir / "image_1", 6},
               options);
    const fs::path calibFile = layout.sequenceDir / "calib.txt";
    requireExists(calibFile, "the KITTI calibration");
    const std::vector<double> left = readCalibrationRow(calibFile, "P0", 12);  // first: errors in file order
    setCamera(left, sensor_ == SensorKind::Stereo ? readCalibrationRow(calibFile, "P1", 12) : std::vector<double>{},
              calibFile, "P1");
    if (fs::exists(layout.posesFile))
      groundTruth_ = readTrajectory(layout.posesFile, TrajectoryFormat::Kitti, timesFile);
  }

  DatasetKind kind() const override { return DatasetKind::Kitti; }
};

}  // namespace

std::unique_ptr<DatasetReader> openKitti(const std::filesystem::path& root, const DatasetOptions& options) {
  return std::make_unique<KittiReader>(root, options);
}

}  // namespace orbis
