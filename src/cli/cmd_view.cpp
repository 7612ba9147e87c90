// orbis view: serves a finished run or a saved map in the live viewer's page.
#include <cstdio>
#include <filesystem>
#include <mutex>

#include "command.hpp"
#include "orbis/util/error.hpp"
#ifdef ORBIS_HAS_VIEWER
#include "orbis/io/map_file.hpp"
#include "orbis/io/ply.hpp"
#include "orbis/io/trajectory.hpp"
#include "orbis/viewer/live_viewer.hpp"
#endif

namespace orbis::cli {
namespace {

namespace fs = std::filesystem;

#ifdef ORBIS_HAS_VIEWER
// An output folder of `orbis run`: keyframes.txt, trajectory.txt and map.ply (no graphs).
MapSnapshot snapshotOfRunOutput(const fs::path& dir) {
  MapSnapshot snapshot;
  const Trajectory keyFrames = readTrajectory(dir / "keyframes.txt", TrajectoryFormat::Tum);
  for (std::size_t i = 0; i < keyFrames.size(); ++i) {
    KeyFrameSnapshot k;
    k.id = i;
    k.Twc = keyFrames[i].pose;
    snapshot.keyFrames.push_back(k);
  }
  const Trajectory trajectory = readTrajectory(dir / "trajectory.txt", TrajectoryFormat::Tum);
  for (const StampedPose& s : trajectory) snapshot.trajectory.push_back(s.pose.translation().cast<float>());
  snapshot.frames = trajectory.size();
  MapPointId id = 0;
  for (const Eigen::Vector3f& p : readPly(dir / "map.ply")) snapshot.points.push_back({id++, p, 0});
  return snapshot;
}

// A map file (io/map_file.hpp), whatever sensor, camera and vocabulary made it.
MapSnapshot snapshotOfMapFile(const fs::path& file) {
  Map map;
  std::lock_guard lock(map.mutex());
  readMapFile(file, map, readMapFileInfo(file));
  MapSnapshot snapshot = snapshotOfMap(map);
  for (const KeyFrameSnapshot& k : snapshot.keyFrames) {
    snapshot.trajectory.push_back(k.Twc.translation().cast<float>());
    snapshot.frames = std::max<std::size_t>(snapshot.frames, k.frameIndex + 1);
  }
  return snapshot;
}
#endif

int viewCommand(const std::vector<std::string>& args) {
  ArgParser p("orbis view OUT_DIR|MAP_FILE [--port PORT]",
              "Serves a finished run (the output folder of orbis run) or a saved map (--save-map) in the\n"
              "viewer's page at http://127.0.0.1:PORT/ until Ctrl-C.");
  p.positional("SOURCE", "an orbis run output folder, or a map file")
      .option("--port", "PORT", "the port to serve on (127.0.0.1 only)", "8080");
  if (!p.parse(args)) return 0;
#ifdef ORBIS_HAS_VIEWER
  const fs::path source = p.pos(0);
  if (!fs::exists(source)) throw fileError(source.string(), "no such file or folder");
  const long port = p.getInt("--port");
  if (port < 1 || port > 65535) throw Error("argument --port", "", "expects a port between 1 and 65535");
  MapSnapshot snapshot = fs::is_directory(source) ? snapshotOfRunOutput(source) : snapshotOfMapFile(source);
  std::printf("%zu keyframes, %zu points\n", snapshot.keyFrames.size(), snapshot.points.size());
  LiveViewer viewer(ViewerOptions{.port = static_cast<int>(port)});
  viewer.show(std::move(snapshot));
  std::printf("viewer: %s (Ctrl-C to stop)\n", viewer.url().c_str());
  std::fflush(stdout);
  waitUntilInterrupted();
  return 0;
#else
  throw Error("orbis view", "", "this orbis was built without the viewer (ORBIS_BUILD_VIEWER)");
#endif
}

ORBIS_REGISTER_COMMAND("view", "serve a finished run or a saved map in the browser viewer", viewCommand);

}  // namespace
}  // namespace orbis::cli
