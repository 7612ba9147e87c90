#include "orbis/synth/sequence.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "orbis/synth/rng.hpp"
#include "orbis/util/error.hpp"

namespace orbis::synth {

namespace {

void require(bool ok, const std::string& key, const std::string& what) {
  if (!ok) throw keyError("synth options", key, what);
}

}  // namespace

void applyScenePreset(ScenePreset preset, RoomParams& room, LoopTrajectoryParams& path) {
  room = RoomParams{};
  path = LoopTrajectoryParams{path.motion};
  if (preset == ScenePreset::Room) return;
  room.min = {-7.0, -5.5, 0.0};
  room.max = {7.0, 5.5, 3.0};
  room.pillarHalf = {3.2, 2.0};
  // The path's ellipse passes 0.9 m outside the block's corners and 1.8-2 m inside the walls;
  // boxes stand between it and the walls.
  path.radiusX = 5.0;
  path.radiusY = 3.7;
  room.freeRadiusX = 5.4;
  room.freeRadiusY = 4.1;
  path.yawOffset = 0.0;  // looking ahead along the corridor
}

SyntheticSequence::SyntheticSequence(const SynthOptions& options)
    : options_(options), renderer_(RenderOptions{options.supersample, 0.0, options.threads}) {
  require(options.frames > 0, "frames", "must be positive");
  require(options.width > 0 && options.height > 0, "resolution", "width and height must be positive");
  require(options.fx > 0.0, "fx", "must be positive");
  require(options.baseline > 0.0, "baseline", "must be positive (metres)");
  require(options.fps > 0.0, "fps", "must be positive");
  require(options.noiseSigma >= 0.0, "noise", "must not be negative");
  require(options.depthNoise >= 0.0, "depth noise", "must not be negative");
  require(options.blurSubframes >= 1, "blur", "must be at least 1 sub-frame");
  require(options.shutter >= 0.0 && options.shutter <= 1.0, "shutter", "must lie in [0, 1]");
  require(options.blackCount >= 0, "black", "count must not be negative");
  require(options.blackCount == 0 || options.blackStart >= 0, "black", "start must not be negative");
  require(options.flatCount >= 0, "flat", "count must not be negative");
  require(options.flatCount == 0 || options.flatStart >= 0, "flat", "start must not be negative");
  require(options.supersample >= 1, "supersample", "must be at least 1");
  require(!options.fisheye || (options.fisheyeFovDegrees >= 10.0 && options.fisheyeFovDegrees <= 240.0), "fov",
          "must lie in [10, 240] degrees");
  scene_ = makeRoomScene(options.room, options.seed);
}

KannalaBrandtCamera<double> SyntheticSequence::fisheyeCamera() const {
  KannalaBrandtCamera<double> c;
  c.k1 = options_.fisheyeK[0], c.k2 = options_.fisheyeK[1], c.k3 = options_.fisheyeK[2], c.k4 = options_.fisheyeK[3];
  c.fx = c.fy = 0.5 * options_.width / c.distortAngle(0.5 * options_.fisheyeFovDegrees * M_PI / 180.0);
  c.cx = 0.5 * options_.width;
  c.cy = 0.5 * options_.height;
  c.width = options_.width;
  c.height = options_.height;
  return c;
}

PinholeCamera<double> SyntheticSequence::camera() const {
  if (options_.fisheye) return fisheyeCamera().centralPinhole();
  PinholeCamera<double> c;
  c.fx = c.fy = options_.fx;
  c.cx = 0.5 * options_.width;
  c.cy = 0.5 * options_.height;
  c.width = options_.width;
  c.height = options_.height;
  return c;
}

std::int64_t SyntheticSequence::timestampNs(int i) const {
  return std::llround(options_.startTime * 1e9) + std::llround(i * 1e9 / options_.fps);
}

SE3d SyntheticSequence::pose(int i) const { return poseAtPhase(static_cast<double>(i) / options_.frames); }

SE3d SyntheticSequence::rightPose(int i) const {
  return pose(i) * SE3d(Eigen::Matrix3d::Identity(), Eigen::Vector3d(options_.baseline, 0.0, 0.0));
}

bool SyntheticSequence::isBlack(int i) const {
  return options_.blackCount > 0 && i >= options_.blackStart && i < options_.blackStart + options_.blackCount;
}

bool SyntheticSequence::isFlat(int i) const {
  return options_.flatCount > 0 && i >= options_.flatStart && i < options_.flatStart + options_.flatCount;
}

cv::Mat SyntheticSequence::renderImage(int i, const SE3d& leftToCamera, int cameraIndex, cv::Mat* depth) {
  const PinholeCamera<double> cam = camera();
  const int n = options_.blurSubframes;
  cv::Mat sum, gray;
  for (int k = 0; k < n; ++k) {
    // Sub-frame instants spread evenly over the open shutter, centred on the frame's instant.
    const double offset = n == 1 ? 0.0 : options_.shutter * ((k + 0.5) / n - 0.5);
    const SE3d subPose = poseAtPhase((i + offset) / options_.frames) * leftToCamera;
    // Depth belongs to the frame's instant: the central sub-frame when there is one.
    const bool centre = n % 2 == 1 && k == n / 2;
    if (options_.fisheye) renderer_.render(scene_, fisheyeCamera(), subPose, gray, centre ? depth : nullptr);
    else renderer_.render(scene_, cam, subPose, gray, centre ? depth : nullptr);
    if (k == 0) sum = gray.clone();
    else sum += gray;
  }
  if (n > 1) sum *= 1.0 / n;
  if (isFlat(i)) sum.setTo(128.0);  // textureless: only the noise is left
  if (depth && n % 2 == 0) {
    // Even sub-frame counts have no sample at the frame's instant: render its depth separately.
    if (options_.fisheye) renderer_.render(scene_, fisheyeCamera(), pose(i) * leftToCamera, gray, depth);
    else renderer_.render(scene_, cam, pose(i) * leftToCamera, gray, depth);
  }
  cv::Mat out(cam.height, cam.width, CV_8UC1);
  SynthRng rng(mixSeed(options_.seed, static_cast<std::uint64_t>(i) + 1, static_cast<std::uint64_t>(cameraIndex) + 1));
  const double sigma = options_.noiseSigma;
  for (int y = 0; y < out.rows; ++y) {
    const float* s = sum.ptr<float>(y);
    std::uint8_t* o = out.ptr<std::uint8_t>(y);
    for (int x = 0; x < out.cols; ++x) {
      const double v = s[x] + (sigma > 0.0 ? sigma * rng.normal() : 0.0);
      o[x] = static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 255.0)));
    }
  }
  return out;
}

SynthFrame SyntheticSequence::render(int i, bool withRight, bool withDepth) {
  SynthFrame f;
  f.index = i;
  f.timestampNs = timestampNs(i);
  f.pose = pose(i);
  f.black = isBlack(i);
  const cv::Size size(options_.width, options_.height);
  if (f.black) {
    f.left = cv::Mat::zeros(size, CV_8UC1);
    if (withRight) f.right = cv::Mat::zeros(size, CV_8UC1);
    if (withDepth) f.depth = cv::Mat::zeros(size, CV_32FC1);
    return f;
  }
  f.left = renderImage(i, SE3d(), 0, withDepth ? &f.depth : nullptr);
  if (withDepth && options_.depthNoise > 0.0) {
    // Noise on inverse depth (the sensor's disparity), its own stream so images stay unchanged.
    SynthRng rng(mixSeed(options_.seed, static_cast<std::uint64_t>(i) + 1, 1000));
    for (int y = 0; y < f.depth.rows; ++y) {
      float* d = f.depth.ptr<float>(y);
      for (int x = 0; x < f.depth.cols; ++x) {
        if (d[x] <= 0.f) continue;
        const double inverse = 1.0 / d[x] + options_.depthNoise * rng.normal();
        d[x] = inverse > 0.0 ? static_cast<float>(1.0 / inverse) : 0.f;
      }
    }
  }
  if (withRight)
    f.right = renderImage(i, SE3d(Eigen::Matrix3d::Identity(), Eigen::Vector3d(options_.baseline, 0.0, 0.0)), 1, nullptr);
  return f;
}

}  // namespace orbis::synth
