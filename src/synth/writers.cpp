#include "orbis/synth/writers.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "orbis/features/orb_params.hpp"
#include "orbis/util/image_file.hpp"
#include "orbis/io/trajectory.hpp"
#include "orbis/util/enum_names.hpp"
#include "orbis/util/error.hpp"

namespace orbis::synth {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

// CPU seconds of the whole process: on a shared machine the honest measure of rendering cost.
double processCpuSeconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

class TextFile {
 public:
  explicit TextFile(fs::path path) : path_(std::move(path)), out_(path_) {
    if (!out_) throw fileError(path_.string(), "cannot open for writing");
  }
  template <class... Args>
  void printf(const char* format, Args... args) {
    char buf[512];
    const int n = std::snprintf(buf, sizeof buf, format, args...);
    out_.write(buf, std::min<std::streamsize>(n, sizeof buf - 1));
  }
  void puts(const std::string& s) { out_ << s; }
  void close() {
    out_.close();
    if (!out_) throw fileError(path_.string(), "write failed");
  }

 private:
  fs::path path_;
  std::ofstream out_;
};

// A YAML real that reads back as a real (cv::FileStorage takes "500" for an integer).
std::string yamlReal(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  std::string s = buf;
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

void makeDirectories(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw fileError(dir.string(), "cannot create directory: " + ec.message());
}

// Depth in metres to TUM's 16-bit PNG (factor 5000); out of range or invalid becomes 0.
cv::Mat tumDepth(const cv::Mat& metres) {
  cv::Mat out(metres.size(), CV_16UC1);
  for (int y = 0; y < metres.rows; ++y) {
    const float* d = metres.ptr<float>(y);
    std::uint16_t* o = out.ptr<std::uint16_t>(y);
    for (int x = 0; x < metres.cols; ++x) {
      const double raw = std::round(static_cast<double>(d[x]) * 5000.0);
      o[x] = (raw > 0.0 && raw <= 65535.0) ? static_cast<std::uint16_t>(raw) : 0;
    }
  }
  return out;
}

void writeEurocSensorYaml(const fs::path& file, const SyntheticSequence& seq, int cameraIndex) {
  const PinholeCamera<double> cam = seq.camera();
  const double shift = cameraIndex == 0 ? 0.0 : seq.options().baseline;
  TextFile f(file);
  f.puts(seq.options().fisheye ? "%YAML:1.0\n# Synthetic fisheye camera written by orbis synth: rectified on load.\n"
                                : "%YAML:1.0\n# Synthetic camera written by orbis synth: already rectified.\n");
  f.puts("sensor_type: camera\n");
  f.printf("comment: orbis synthetic cam%d\n\n", cameraIndex);
  f.puts("# Sensor extrinsics wrt. the body-frame (body = cam0).\nT_BS:\n  cols: 4\n  rows: 4\n");
  f.printf("  data: [1.0, 0.0, 0.0, %.9f,\n         0.0, 1.0, 0.0, 0.0,\n         0.0, 0.0, 1.0, 0.0,\n"
           "         0.0, 0.0, 0.0, 1.0]\n\n", shift);
  f.printf("rate_hz: %g\nresolution: [%d, %d]\ncamera_model: pinhole\n", seq.options().fps, cam.width, cam.height);
  f.puts("intrinsics: [" + yamlReal(cam.fx) + ", " + yamlReal(cam.fy) + ", " + yamlReal(cam.cx) + ", " +
         yamlReal(cam.cy) + "] #fu, fv, cu, cv\n");
  if (seq.options().fisheye) {
    // Kalibr's (and TUM-VI's) name for the Kannala-Brandt model.
    const KannalaBrandtCamera<double> lens = seq.fisheyeCamera();
    f.puts("distortion_model: equidistant\ndistortion_coefficients: [" + yamlReal(lens.k1) + ", " + yamlReal(lens.k2) +
           ", " + yamlReal(lens.k3) + ", " + yamlReal(lens.k4) + "]\n");
  } else {
    f.puts("distortion_model: radial-tangential\ndistortion_coefficients: [0.0, 0.0, 0.0, 0.0]\n");
  }
  f.close();
}

void writeKittiCalib(const fs::path& file, const SyntheticSequence& seq) {
  const PinholeCamera<double> c = seq.camera();
  TextFile f(file);
  for (int i = 0; i < 2; ++i) {
    const double tx = i == 0 ? 0.0 : -c.fx * seq.options().baseline;
    f.printf("P%d: %.12e %.12e %.12e %.12e %.12e %.12e %.12e %.12e %.12e %.12e %.12e %.12e\n", i, c.fx, 0.0, c.cx,
             tx, 0.0, c.fy, c.cy, 0.0, 0.0, 0.0, 1.0, 0.0);
  }
  f.close();
}

}  // namespace

namespace {
constexpr EnumName<SynthLayout> kSynthLayoutNames[] = {
    {SynthLayout::Tum, "tum"}, {SynthLayout::Euroc, "euroc"}, {SynthLayout::Kitti, "kitti"}};
}  // namespace

SynthLayout parseSynthLayout(std::string_view name, const std::string& source) {
  return parseEnumName(kSynthLayoutNames, name, "layout", source);
}

std::string_view toString(SynthLayout layout) { return enumName(kSynthLayoutNames, layout); }

void writeSynthSettings(const fs::path& file, const SyntheticSequence& seq, std::string_view sensor) {
  const SynthOptions& o = seq.options();
  const PinholeCamera<double> c = seq.camera();
  const OrbParams orb;
  TextFile f(file);
  f.puts("%YAML:1.0\n");
  f.puts("# Synthetic sequence written by orbis synth (ORB-SLAM2 settings keys).\n");
  f.printf("Sensor: \"%s\"\n", std::string(sensor).c_str());
  // The system's seed is a 31-bit integer in the settings; the scene seed is folded into it.
  f.printf("System.seed: %llu\n\n", static_cast<unsigned long long>(o.seed & 0x7fffffffULL));
  f.puts("Camera.fx: " + yamlReal(c.fx) + "\nCamera.fy: " + yamlReal(c.fy) + "\nCamera.cx: " + yamlReal(c.cx) +
         "\nCamera.cy: " + yamlReal(c.cy) + "\n\n");
  if (o.fisheye) {
    const KannalaBrandtCamera<double> lens = seq.fisheyeCamera();
    f.puts("# Kannala-Brandt (equidistant fisheye) lens, ORB-SLAM3's keys.\nCamera.type: \"KannalaBrandt8\"\n");
    f.puts("Camera.k1: " + yamlReal(lens.k1) + "\nCamera.k2: " + yamlReal(lens.k2) + "\nCamera.k3: " +
           yamlReal(lens.k3) + "\nCamera.k4: " + yamlReal(lens.k4) + "\n\n");
  } else {
    f.puts("Camera.k1: 0.0\nCamera.k2: 0.0\nCamera.p1: 0.0\nCamera.p2: 0.0\nCamera.k3: 0.0\n\n");
  }
  f.printf("Camera.width: %d\nCamera.height: %d\n\n", c.width, c.height);
  f.puts("Camera.fps: " + yamlReal(o.fps) + "\n\n");
  f.puts("# Stereo baseline times fx (virtual for RGB-D).\n");
  if (!o.fisheye) f.puts("Camera.bf: " + yamlReal(c.fx * o.baseline) + "\n\n");
  f.puts("# Colour order of the images (0: BGR, 1: RGB); they are grey.\nCamera.RGB: 1\n\n");
  f.puts("# Close/far threshold, in baselines.\nThDepth: 40.0\n\n");
  if (sensor == "rgbd") f.puts("# Raw depth value / DepthMapFactor = metres.\nDepthMapFactor: 5000.0\n\n");
  f.printf("ORBextractor.nFeatures: %d\n", orb.features);
  f.puts("ORBextractor.scaleFactor: " + yamlReal(std::round(orb.scaleFactor * 1e6) / 1e6) + "\n");
  f.printf("ORBextractor.nLevels: %d\nORBextractor.iniThFAST: %d\nORBextractor.minThFAST: %d\n", orb.levels,
           orb.iniThFast, orb.minThFast);
  f.close();
}

SynthWriteResult writeSynthSequence(SyntheticSequence& seq, SynthLayout layout, const fs::path& outDir,
                                    const std::function<void(int)>& onFrame) {
  const auto start = Clock::now();
  SynthWriteResult result;
  result.root = outDir;
  makeDirectories(outDir);
  const int n = seq.totalFrames();
  const bool stereo = layout != SynthLayout::Tum;
  const bool depth = layout == SynthLayout::Tum;

  fs::path leftDir, rightDir, depthDir, seqDir;
  std::vector<std::string> leftIndex, depthIndex;
  switch (layout) {
    case SynthLayout::Tum:
      leftDir = outDir / "rgb";
      depthDir = outDir / "depth";
      makeDirectories(depthDir);
      result.groundTruth = outDir / "groundtruth.txt";
      break;
    case SynthLayout::Euroc:
      leftDir = outDir / "mav0" / "cam0" / "data";
      rightDir = outDir / "mav0" / "cam1" / "data";
      makeDirectories(outDir / "mav0" / "state_groundtruth_estimate0");
      result.groundTruth = outDir / "mav0" / "state_groundtruth_estimate0" / "data.csv";
      break;
    case SynthLayout::Kitti:
      seqDir = outDir / "sequences" / "00";
      leftDir = seqDir / "image_0";
      rightDir = seqDir / "image_1";
      makeDirectories(outDir / "poses");
      result.groundTruth = outDir / "poses" / "00.txt";
      break;
  }
  makeDirectories(leftDir);
  if (stereo) makeDirectories(rightDir);

  Trajectory groundTruth;
  std::vector<double> times;
  double renderSeconds = 0.0, renderCpuSeconds = 0.0;
  const SE3d firstInverse = seq.pose(0).inverse();
  for (int i = 0; i < n; ++i) {
    const auto t0 = Clock::now();
    const double cpu0 = processCpuSeconds();
    const SynthFrame frame = seq.render(i, stereo, depth);
    renderSeconds += std::chrono::duration<double>(Clock::now() - t0).count();
    renderCpuSeconds += processCpuSeconds() - cpu0;
    const double t = seq.timestamp(i);
    char name[64];
    switch (layout) {
      case SynthLayout::Tum:
        std::snprintf(name, sizeof name, "%.6f.png", t);
        writeImageFile(leftDir / name, frame.left);
        writeImageFile(depthDir / name, tumDepth(frame.depth));
        leftIndex.push_back(name);
        groundTruth.push_back({t, frame.pose});
        break;
      case SynthLayout::Euroc:
        std::snprintf(name, sizeof name, "%lld.png", static_cast<long long>(frame.timestampNs));
        writeImageFile(leftDir / name, frame.left);
        writeImageFile(rightDir / name, frame.right);
        leftIndex.push_back(name);
        groundTruth.push_back({t, frame.pose});
        break;
      case SynthLayout::Kitti:
        std::snprintf(name, sizeof name, "%06d.png", i);
        writeImageFile(leftDir / name, frame.left);
        writeImageFile(rightDir / name, frame.right);
        groundTruth.push_back({t - seq.timestamp(0), firstInverse * frame.pose});
        break;
    }
    times.push_back(t);
    result.blackFrames += frame.black ? 1 : 0;
    ++result.frames;
    if (onFrame) onFrame(i + 1);
  }

  switch (layout) {
    case SynthLayout::Tum: {
      for (const char* kind : {"rgb", "depth"}) {
        TextFile f(outDir / (std::string(kind) + ".txt"));
        f.printf("# %s\n# file: 'orbis synth, seed %llu'\n# timestamp filename\n",
                 std::string(kind) == "rgb" ? "color images" : "depth maps",
                 static_cast<unsigned long long>(seq.options().seed));
        for (int i = 0; i < n; ++i)
          f.printf("%.6f %s/%s\n", times[static_cast<std::size_t>(i)], kind, leftIndex[static_cast<std::size_t>(i)].c_str());
        f.close();
      }
      writeTrajectory(result.groundTruth, groundTruth, TrajectoryFormat::Tum);
      break;
    }
    case SynthLayout::Euroc: {
      for (int cam = 0; cam < 2; ++cam) {
        const fs::path camDir = outDir / "mav0" / ("cam" + std::to_string(cam));
        TextFile f(camDir / "data.csv");
        f.puts("#timestamp [ns],filename\n");
        for (int i = 0; i < n; ++i)
          f.printf("%lld,%s\n", static_cast<long long>(seq.timestampNs(i)), leftIndex[static_cast<std::size_t>(i)].c_str());
        f.close();
        writeEurocSensorYaml(camDir / "sensor.yaml", seq, cam);
      }
      writeTrajectory(result.groundTruth, groundTruth, TrajectoryFormat::Euroc);
      break;
    }
    case SynthLayout::Kitti: {
      TextFile f(seqDir / "times.txt");
      for (int i = 0; i < n; ++i) f.printf("%.6e\n", times[static_cast<std::size_t>(i)] - times[0]);
      f.close();
      writeKittiCalib(seqDir / "calib.txt", seq);
      writeTrajectory(result.groundTruth, groundTruth, TrajectoryFormat::Kitti);
      break;
    }
  }
  result.settings = outDir / "settings.yaml";
  result.settingsMono = outDir / "settings_mono.yaml";
  // A fisheye runs monocular from settings; its stereo pair is rectified on load from sensor.yaml.
  writeSynthSettings(result.settings, seq, seq.options().fisheye ? "mono" : layout == SynthLayout::Tum ? "rgbd" : "stereo");
  writeSynthSettings(result.settingsMono, seq, "mono");
  result.renderSeconds = renderSeconds;
  result.renderCpuSeconds = renderCpuSeconds;
  result.totalSeconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

}  // namespace orbis::synth
