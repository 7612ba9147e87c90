// orbis/synth/sequence.hpp — synthetic image sequences with exact ground truth.
//
// Contract: a SyntheticSequence renders frame i of the room scene (makeRoomScene) seen along
// one loop of loopPose(): frame i has phase i / frames, timestamp startTime + i / fps (held
// as integer nanoseconds, so every dataset layout writes the same instants), and ground truth
// pose(i) = T_wc of the left camera. The right camera of the rectified stereo pair sits at
// +baseline along the left camera's x axis with the same orientation and intrinsics; depth is
// metric along the left optical axis. With options.fisheye every image (left and right) is
// rendered through fisheyeCamera() instead. Images are CV_8UC1: the rendered grey levels, averaged
// over blurSubframes renders spread over `shutter` of the frame interval centred on the
// frame's instant (motion blur), plus Gaussian noise of noiseSigma grey levels, rounded and
// clamped; depth gets Gaussian noise of depthNoise on its inverse. Frames blackStart ..
// blackStart+blackCount-1 are all black with zero (invalid) depth, but keep their pose (the camera was covered). Everything is a function of the
// options and the seed: the same options give byte-identical frames, in any order (render()
// changes nothing but its renderer's scratch buffers; use one sequence object per thread).
#pragma once

#include <array>
#include <cstdint>

#include <opencv2/core.hpp>

#include "orbis/camera/kannala_brandt.hpp"
#include "orbis/camera/pinhole.hpp"
#include "orbis/geometry/se3.hpp"
#include "orbis/synth/loop_trajectory.hpp"
#include "orbis/synth/renderer.hpp"
#include "orbis/synth/scene.hpp"

namespace orbis::synth {

// The scene and path presets `orbis synth --scene` offers. Room: the standard room (defaults of
// RoomParams and LoopTrajectoryParams), its 11 m loop looking outwards at walls 2-3 m away, each
// wall in view for a large part of the loop. Corridor: a 14 x 11 m floor round a 6.4 x 4 m
// central block, a 27 m loop between them with the camera looking ahead along the corridor, as
// real loop sequences are walked or driven: what the camera sees at the start is hidden behind
// the block for most of the loop, so the drift of a monocular map builds up as in a real loop
// before it comes back.
enum class ScenePreset { Room, Corridor };
// Sets a preset's room and path.
void applyScenePreset(ScenePreset preset, RoomParams& room, LoopTrajectoryParams& path);

// What orbis synth renders (its options map onto these fields).
struct SynthOptions {
  // Frames in one loop.
  int frames = 300;
  int extraFrames = 0;  // written past the loop's end: the path repeats, so the camera goes on over
  // @{
                        // known ground (loop detection needs a few keyframes there)
  int width = 640, height = 480;
  // @}
  double fx = 500.0;             // fy = fx; principal point at the image centre
  double baseline = 0.1;         // metres, right camera at +baseline along x
  // Frames per second.
  double fps = 30.0;
  double startTime = 1.0;        // seconds, timestamp of frame 0
  double noiseSigma = 0.0;       // grey levels
  // Depth-sensor noise: σ of inverse depth, 1/m, per pixel, as a structured-light sensor measures
  // disparity (a Kinect's σ_z ≈ 1.4e-3 z², i.e. about 0.0014 here). 0: exact depth.
  double depthNoise = 0.0;
  int blurSubframes = 1;         // 1: no motion blur
  double shutter = 0.5;          // fraction of the frame interval the shutter is open
  // @{
  // Black frames from blackStart, blackCount of them (relocalisation tests).
  int blackStart = -1, blackCount = 0;
  // @}
  // @{
  // Frames flatStart .. flatStart+flatCount-1 see a textureless world: uniform grey (plus the
  // image noise); depth and pose as rendered.
  int flatStart = -1, flatCount = 0;
  // @}
  // @{
  // Seed of the scene, textures and noise; rays per pixel along each axis; rendering threads; the
  // room and the path.
  std::uint64_t seed = 1;
  // Fisheye: render through a Kannala–Brandt lens (fisheyeCamera()) instead of the pinhole; fx is
  // then derived so that the image's width spans fisheyeFovDegrees through the principal point.
  bool fisheye = false;
  double fisheyeFovDegrees = 180.0;
  std::array<double, 4> fisheyeK{0.01, -0.002, 0.0005, 0.0};  // k1..k4, monotonic to well past 120°
  int supersample = 2;
  int threads = 1;
  RoomParams room;
  LoopTrajectoryParams path;
  // @}
};

// One rendered frame.
struct SynthFrame {
  // @{
  // Index and timestamp (ns).
  int index = 0;
  std::int64_t timestampNs = 0;
  // @}
  SE3d pose;        // T_wc of the left camera
  // Whether the frame is blacked out.
  bool black = false;
  cv::Mat left;     // CV_8UC1
  cv::Mat right;    // CV_8UC1, when asked
  cv::Mat depth;    // CV_32FC1 metres (0 = invalid), when asked
};

// A rendered sequence with exact ground truth: the scene, the camera path and frames rendered on
// demand.
class SyntheticSequence {
 public:
  // Throws orbis::Error("synth options", key, ...) for a non-positive size, frame count, fps,
  // focal length or baseline, or a negative noise or black segment.
  explicit SyntheticSequence(const SynthOptions& options);

  // @{
  // The options, the scene, the left camera, frames in one loop, and frames written (the loop plus
  // extra ones).
  const SynthOptions& options() const { return options_; }
  const Scene& scene() const { return scene_; }
  PinholeCamera<double> camera() const;  // fisheye: the lens's tangent-plane pinhole
  KannalaBrandtCamera<double> fisheyeCamera() const;  // meaningful when options().fisheye
  int size() const { return options_.frames; }  // one loop
  int totalFrames() const { return options_.frames + options_.extraFrames; }  // what writers write
  // @}

  // @{
  // A frame's timestamp in nanoseconds and in seconds.
  std::int64_t timestampNs(int i) const;
  double timestamp(int i) const { return static_cast<double>(timestampNs(i)) * 1e-9; }
  // @}
  SE3d pose(int i) const;               // T_wc, left camera
  SE3d rightPose(int i) const;          // T_wc, right camera
  // @{
  // Whether a frame is blacked out or textureless.
  bool isBlack(int i) const;
  bool isFlat(int i) const;
  // @}

  // Renders frame i (the right image and the depth when asked).
  SynthFrame render(int i, bool withRight, bool withDepth);

 private:
  SE3d poseAtPhase(double phase) const { return loopPose(options_.path, phase); }
  cv::Mat renderImage(int i, const SE3d& leftToRight, int cameraIndex, cv::Mat* depth);

  SynthOptions options_;
  Scene scene_;
  Renderer renderer_;
};

}  // namespace orbis::synth
