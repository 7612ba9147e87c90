// The smallest useful orbis program: RGB-D SLAM over a TUM-layout folder through the library API
// (no dataset runner), printing each frame's tracking state and camera position.
//
//   rgbd_slam PATH_TO_TUM_SEQUENCE [VOCABULARY]
//
// The sensor configuration is a type: Slam<Rgbd> compiles only the RGB-D code path (camera
// model, feature builder, residuals); Slam<Stereo> would take rectified pairs instead.
#include <cstdio>
#include <exception>

#include "orbis/adapters/dataset.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/system/slam.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s TUM_SEQUENCE [VOCABULARY]\n", argv[0]);
    return 2;
  }
  try {
    auto dataset = orbis::openDataset(orbis::DatasetKind::TumRgbd, argv[1]);
    const auto camera = std::get<orbis::RgbdCamera<double>>(dataset->camera());
    auto vocabulary = std::make_shared<const orbis::OrbVocabulary>(
        orbis::OrbVocabulary::load(argc > 2 ? argv[2] : orbis::defaultVocabularyPath()));

    orbis::OrbParams orb;  // ORB-SLAM2's defaults: 1000 features, 8 levels, factor 1.2
    orbis::SlamOptions options;
    options.deterministic = true;  // same input, same trajectory
    orbis::Slam<orbis::Rgbd> slam(camera, orb, vocabulary, options);

    while (auto frame = dataset->next()) {
      if (frame->depth.empty()) continue;  // no depth map within 20 ms of this colour image
      const orbis::TrackResult r = slam.track({frame->timestamp, frame->left, frame->depth});
      const Eigen::Vector3d centre = r.Tcw.inverse().translation();
      std::printf("%.6f %-8s %+.3f %+.3f %+.3f\n", frame->timestamp, orbis::toString(r.state), centre.x(),
                  centre.y(), centre.z());
    }
    slam.shutdown();
    const orbis::SlamStats s = slam.stats();
    std::printf("# %zu frames, %zu tracked, %zu keyframes, %zu map points\n", s.frames, s.tracked, s.keyFrames,
                s.mapPoints);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
