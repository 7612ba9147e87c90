// orbis/viewer/live_viewer.hpp — a live 3-D view of SLAM in the browser.
//
// Contract: LiveViewer serves one page (three.js and the page are compiled into the library: it
// works offline) on host:port, 127.0.0.1 by default, and streams the scene to it as server-sent
// events of JSON. It is a SlamObserver (viewer/slam_observer.hpp): onFrame() only moves the
// snapshot into a one-slot mailbox and returns; a publisher thread of its own turns the latest
// frame into a message at most frameRateHz times a second (with its image scaled down and JPEG-
// encoded there, never on the tracking thread; the frames in between are dropped, and no new
// frame is encoded while no browser has been sent the previous one) and takes a map snapshot at
// mapRateHz, and only while a browser is connected. A browser is sent the whole map when it
// connects, then what changed since the previous map message (src/viewer/map_delta.hpp); one that
// lags further behind than the recent changes kept is sent the whole map again. Each browser gets
// the newest frame: a slow or vanished browser misses updates, never delays tracking. The viewer's
// threads (publisher, server) run at the lowest priority (nice 19 on Linux): best-effort work
// yields the cores to SLAM. detach() or show() publish a final map, which the page keeps showing
// until the viewer is destroyed. The constructor throws orbis::Error when the port cannot be
// bound; the destructor stops the server and threads.
#pragma once

#include <memory>
#include <string>

#include "orbis/viewer/slam_observer.hpp"

namespace orbis {

// Where and how often the viewer serves.
struct ViewerOptions {
  // @{
  // The address it listens on (loopback only) and the port.
  std::string host = "127.0.0.1";
  int port = 8080;
  // @}
  // Frame messages (keypoints, pose, timing, image) per second, at most: the page draws streamed
  // updates 5 times a second (a browser on the SLAM machine takes its CPU from tracking).
  double frameRateHz = 5;
  double mapRateHz = 5;     // map snapshots per second, at most
  int imageMaxWidth = 320;  // the camera image, scaled down to this width as JPEG; 0: no image
  // JPEG quality of the camera image.
  int jpegQuality = 70;
};

// What the viewer did, for the overhead it adds: messages built and the CPU time of its
// publisher thread (snapshots and JSON; the server's threads only copy bytes to sockets).
struct ViewerStats {
  // @{
  // Frame and map messages, bytes sent, and the CPU time of the publisher thread.
  std::size_t frameMessages = 0, mapMessages = 0, bytes = 0;
  double publisherCpuSeconds = 0;
  // @}
};

// The live browser viewer: an HTTP server with the page (three.js, compiled in) and a
// server-sent-events stream of frames and map changes.
class LiveViewer final : public SlamObserver {
 public:
  // Starts serving at options.host:options.port; throws orbis::Error when the port is taken.
  explicit LiveViewer(ViewerOptions options = {});
  ~LiveViewer() override;
  LiveViewer(const LiveViewer&) = delete;
  LiveViewer& operator=(const LiveViewer&) = delete;

  // The page's address.
  std::string url() const;
  // What it has sent so far.
  ViewerStats stats() const;

  void attach(MapSnapshotSource source) override;
  void onFrame(FrameSnapshot&& frame) override;
  // The run ended: keeps serving its final map.
  void detach(MapSnapshot finalMap) override;
  // A finished run or a saved map, without SLAM: serve this map (orbis view).
  void show(MapSnapshot map);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace orbis
