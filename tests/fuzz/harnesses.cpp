// The parsers' fuzz harnesses; see harnesses.hpp.
#include "harnesses.hpp"

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "orbis/adapters/dataset.hpp"
#include "orbis/bow/dbow2_text.hpp"
#include "orbis/bow/vocabulary.hpp"
#include "orbis/bow/vocabulary_file.hpp"
#include "orbis/camera/euroc_calibration.hpp"
#include "orbis/io/bal.hpp"
#include "orbis/io/map_file.hpp"
#include "orbis/io/settings.hpp"
#include "orbis/io/trajectory.hpp"
#include "orbis/util/error.hpp"
#include "../map_file_bytes.hpp"

namespace orbis::fuzz {
namespace {

namespace fs = std::filesystem;

// One scratch folder per process, made once: its companion files are written on first use.
const fs::path& scratch() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("orbis_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

fs::path writeFile(const fs::path& relative, const void* data, std::size_t size) {
  const fs::path file = scratch() / relative;
  fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  return file;
}

fs::path writeText(const fs::path& relative, const std::string& text) {
  return writeFile(relative, text.data(), text.size());
}

void writeImage(const fs::path& relative) {
  const fs::path file = scratch() / relative;
  if (fs::exists(file)) return;
  fs::create_directories(file.parent_path());
  cv::imwrite(file.string(), cv::Mat(8, 8, CV_8UC1, cv::Scalar(100)));
}

void trajectory(const std::uint8_t* data, std::size_t size, const char* name, TrajectoryFormat format) {
  std::vector<std::string> warnings;
  readTrajectory(writeFile(name, data, size), format, {}, &warnings);
}

void tumTrajectory(const std::uint8_t* d, std::size_t n) { trajectory(d, n, "traj.txt", TrajectoryFormat::Tum); }
void eurocTrajectory(const std::uint8_t* d, std::size_t n) { trajectory(d, n, "traj.csv", TrajectoryFormat::Euroc); }
void kittiTrajectory(const std::uint8_t* d, std::size_t n) { trajectory(d, n, "poses.txt", TrajectoryFormat::Kitti); }

void detectedTrajectory(const std::uint8_t* data, std::size_t size) {
  const fs::path file = writeFile("any.txt", data, size);
  std::vector<std::string> warnings;
  readTrajectory(file, detectTrajectoryFormat(file), {}, &warnings);
}

void kittiTimes(const std::uint8_t* data, std::size_t size) { readTimestamps(writeFile("times.txt", data, size)); }

void eurocSensorYaml(const std::uint8_t* data, std::size_t size) {
  readEurocCalibration(writeFile("sensor.yaml", data, size));
}

void settingsYaml(const std::uint8_t* data, std::size_t size) { Settings::load(writeFile("settings.yaml", data, size)); }

void bal(const std::uint8_t* data, std::size_t size) { readBal(writeFile("problem.bal", data, size)); }

// The TUM lists as rgb.txt (monocular: no depth list needed), rows read even without images.
void tumList(const std::uint8_t* data, std::size_t size) {
  writeFile("tum/rgb.txt", data, size);
  DatasetOptions options;
  options.sensor = SensorKind::Monocular;
  options.tolerateBadFrames = true;
  openTumRgbd(scratch() / "tum", options);
}

void eurocList(const std::uint8_t* data, std::size_t size) {
  writeFile("euroc/mav0/cam0/data.csv", data, size);
  writeText("euroc/mav0/cam0/sensor.yaml",
            "T_BS:\n  cols: 4\n  rows: 4\n  data: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n"
            "resolution: [8, 8]\ncamera_model: pinhole\nintrinsics: [5, 5, 4, 4]\n"
            "distortion_model: radial-tangential\ndistortion_coefficients: [0, 0, 0, 0]\n");
  DatasetOptions options;
  options.sensor = SensorKind::Monocular;
  options.tolerateBadFrames = true;
  options.rectify = false;
  openEuroc(scratch() / "euroc", options);
}

void kittiCalib(const std::uint8_t* data, std::size_t size) {
  writeFile("kitti/calib.txt", data, size);
  writeText("kitti/times.txt", "0.0\n");
  writeImage("kitti/image_0/000000.png");
  writeImage("kitti/image_1/000000.png");
  openKitti(scratch() / "kitti", {});
}

void kittiRawCalib(const std::uint8_t* data, std::size_t size) {
  writeFile("raw/calib_cam_to_cam.txt", data, size);
  writeText("raw/image_00/timestamps.txt", "2011-09-26 13:02:25.964389445\n");
  writeImage("raw/image_00/data/0000000000.png");
  writeImage("raw/image_01/data/0000000000.png");
  openKittiRaw(scratch() / "raw", {});
}

// oxts/timestamps.txt and the first packet from the input, split at its first newline.
void kittiRawOxts(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::size_t split = std::min(text.find('\n'), text.size());
  writeText("oxts/calib_cam_to_cam.txt", "P_rect_00: 7 0 4 0 0 7 4 0 0 0 1 0\nR_rect_00: 1 0 0 0 1 0 0 0 1\n");
  writeText("oxts/calib_imu_to_velo.txt", "R: 1 0 0 0 1 0 0 0 1\nT: 0 0 0\n");
  writeText("oxts/calib_velo_to_cam.txt", "R: 1 0 0 0 1 0 0 0 1\nT: 0 0 0\n");
  writeText("oxts/image_00/timestamps.txt", "2011-09-26 13:02:25.964389445\n");
  writeImage("oxts/image_00/data/0000000000.png");
  writeText("oxts/oxts/timestamps.txt", text.substr(0, split) + "\n");
  writeText("oxts/oxts/data/0000000000.txt", split < text.size() ? text.substr(split + 1) : std::string());
  DatasetOptions options;
  options.sensor = SensorKind::Monocular;
  openKittiRaw(scratch() / "oxts", options);
}

void kittiRawTimestamps(const std::uint8_t* data, std::size_t size) {
  writeFile("rawtimes/image_00/timestamps.txt", data, size);
  writeImage("rawtimes/image_00/data/0000000000.png");
  writeText("rawtimes/calib_cam_to_cam.txt", "P_rect_00: 7 0 4 0 0 7 4 0 0 0 1 0\n");
  DatasetOptions options;
  options.sensor = SensorKind::Monocular;
  options.tolerateBadFrames = true;
  openKittiRaw(scratch() / "rawtimes", options);
}

void vocabularyBinary(const std::uint8_t* data, std::size_t size) {
  bow::OrbVocabulary::load(writeFile("vocabulary.bin", data, size));
}

// The same with the checksum trailer recomputed, so mutations reach the structure checks behind it.
void vocabularyBinaryResealed(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> bytes(data, data + size);
  if (bytes.size() >= 72) {
    const std::uint64_t sum = bow::checksum64(bytes.data(), bytes.size() - 8);
    std::memcpy(bytes.data() + bytes.size() - 8, &sum, sizeof sum);  // little-endian, as the format
  }
  bow::OrbVocabulary::load(writeFile("vocabulary_resealed.bin", bytes.data(), bytes.size()));
}

// A map file with its declared size and checksum trailer recomputed (../map_file_bytes.hpp), so
// mutations reach the structure checks behind the checksum. The file is loaded against its own
// header, as `orbis view` does, so every field is reached.
void mapFile(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> bytes(data, data + size);
  test::resealMapFile(bytes);
  const fs::path file = writeFile("orbis.map", bytes.data(), bytes.size());
  const MapFileInfo info = readMapFileInfo(file);
  Map map;
  std::lock_guard lock(map.mutex());
  readMapFile(file, map, info);
}

void vocabularyText(const std::uint8_t* data, std::size_t size) {
  bow::readDbow2Text<bow::OrbVocabulary>(writeFile("vocabulary.txt", data, size));
}

}  // namespace

const std::vector<Harness>& harnesses() {
  static const std::vector<Harness> all = {
      {"tum_trajectory", tumTrajectory},
      {"euroc_trajectory", eurocTrajectory},
      {"kitti_trajectory", kittiTrajectory},
      {"detected_trajectory", detectedTrajectory},
      {"kitti_times", kittiTimes},
      {"euroc_sensor_yaml", eurocSensorYaml},
      {"settings_yaml", settingsYaml},
      {"bal", bal},
      {"tum_list", tumList},
      {"euroc_list", eurocList},
      {"kitti_calib", kittiCalib},
      {"kitti_raw_calib", kittiRawCalib},
      {"kitti_raw_oxts", kittiRawOxts},
      {"kitti_raw_timestamps", kittiRawTimestamps},
      {"vocabulary_binary", vocabularyBinary},
      {"vocabulary_binary_resealed", vocabularyBinaryResealed},
      {"vocabulary_text", vocabularyText},
      {"map_file", mapFile},
  };
  return all;
}

const Harness* findHarness(std::string_view name) {
  for (const Harness& h : harnesses())
    if (h.name == name) return &h;
  return nullptr;
}

}  // namespace orbis::fuzz
