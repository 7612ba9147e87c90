// orbis/synth/renderer.hpp — a ray caster that renders grey images and depth of a Scene.
//
// Contract: render() draws what an ideal pinhole camera at pose cameraToWorld (T_wc) sees of
// the scene. Pixel (i, j) is centred on image coordinates (u, v) = (i, j), the convention of
// PinholeCamera::project, and its grey value is the mean of supersample x supersample rays on a
// regular grid inside the pixel, each sampling its texture trilinearly at the mip level of the
// ray spacing (antialiasing of both silhouettes and texture). gray: CV_32FC1, grey levels
// 0..255. depth (when asked): CV_32FC1, metres along the optical axis of the ray through the
// pixel centre, 0 where no surface is hit. Per frame, rectangles facing away are culled and
// the rest are binned into 16x16-pixel tiles by their clipped projected bounds, so each ray
// tests only the few rectangles that can cover it. A Renderer keeps scratch buffers: use one
// per thread. `threads` > 1 splits the rows among that many threads; the result is identical.
// The Kannala–Brandt overload renders through a fisheye lens instead: each sample's ray is the
// lens's exact unprojection (camera/kannala_brandt.hpp), rays past the lens's maxAngle are black,
// depth is still z along the optical axis (negative behind the image plane), and rectangles are
// binned by their edges projected through the lens (a rectangle across the backward axis covers
// every tile).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "orbis/camera/kannala_brandt.hpp"
#include "orbis/camera/pinhole.hpp"
#include "orbis/geometry/se3.hpp"
#include "orbis/synth/scene.hpp"

namespace orbis::synth {

// How frames are rendered.
struct RenderOptions {
  int supersample = 2;   // rays per pixel along each axis
  double lodBias = 0.0;  // added to every mip level (positive: blurrier)
  // Rendering threads.
  int threads = 1;
};

// A ray caster for axis-aligned textured rectangles, with mip-mapped, supersampled texture lookups.
class Renderer {
 public:
  // A renderer with these options.
  explicit Renderer(RenderOptions options = {}) : options_(options) {}

  // Renders the grey image (and, when asked, the depth in metres) of scene through camera at
  // cameraToWorld.
  void render(const Scene& scene, const PinholeCamera<double>& camera, const SE3d& cameraToWorld,
              cv::Mat& gray, cv::Mat* depth = nullptr);
  // The same through a fisheye lens.
  void render(const Scene& scene, const KannalaBrandtCamera<double>& camera, const SE3d& cameraToWorld,
              cv::Mat& gray, cv::Mat* depth = nullptr);

  // The options.
  const RenderOptions& options() const { return options_; }

  // One rectangle as the hot loop sees it in the current frame.
  struct FrameRect {
    // @{
    // The rectangle's axis, in-plane axes, plane offset, bounds, texel scale and texture.
    int axis, u, v;
    double offset, lo0, lo1, hi0, hi1, invTexel, lodScale;
    const Texture* texture;
    // @}
  };

 private:
  void binRects(const Scene& scene, const PinholeCamera<double>& camera, const SE3d& cameraToWorld);
  void renderRows(const PinholeCamera<double>& camera, const SE3d& cameraToWorld, int rowBegin, int rowEnd,
                  cv::Mat& gray, cv::Mat* depth) const;
  void binRectsFisheye(const Scene& scene, const KannalaBrandtCamera<double>& camera, const SE3d& cameraToWorld);
  void renderRowsFisheye(const KannalaBrandtCamera<double>& camera, const SE3d& cameraToWorld, int rowBegin,
                         int rowEnd, cv::Mat& gray, cv::Mat* depth) const;
  template <class RenderRows>
  void renderInThreads(int height, const RenderRows& rows);
  // Walks rows [rowBegin, rowEnd) of a width-pixel image: shade(x, y, tileList, tileCount) gives
  // the pixel's grey value, and depthOf(x, y, tileList, tileCount) its depth when `depth` is asked.
  template <class Shade, class DepthOf>
  void forEachPixel(int rowBegin, int rowEnd, int width, cv::Mat& gray, cv::Mat* depth, const Shade& shade,
                    const DepthOf& depthOf) const;
  template <class BoundsOf>
  void binWith(const Scene& scene, int width, int height, double focal, const SE3d& cameraToWorld,
               const BoundsOf& boundsOf);
  void prepareFisheyeRays(const KannalaBrandtCamera<double>& camera);

  RenderOptions options_;
  std::vector<FrameRect> frameRects_;
  int tilesX_ = 0, tilesY_ = 0;
  std::vector<int> tileBegin_;     // tile t's rectangles: tileRects_[tileBegin_[t] .. tileBegin_[t+1])
  std::vector<int> tileRects_;
  // The fisheye's unit rays per sample (row-major, supersample² per pixel; z = 2: outside the
  // lens's field of view), kept while the lens stays the same.
  std::vector<Eigen::Vector3d> fisheyeRays_;
  KannalaBrandtCamera<double> fisheyeRaysOf_;
};

}  // namespace orbis::synth
