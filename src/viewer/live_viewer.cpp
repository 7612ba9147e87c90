#include "orbis/viewer/live_viewer.hpp"

#include <httplib.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>
#include <time.h>
#ifdef __linux__
#include <sys/resource.h>
#include <unistd.h>
#endif
#include <unordered_set>

#include "orbis/util/error.hpp"
#include "orbis/util/thread_scheduling.hpp"
#include "frame_image.hpp"
#include "map_delta.hpp"
#include "scene_json.hpp"
#include "web_assets.hpp"

namespace orbis {

using namespace viewer_detail;
using Clock = std::chrono::steady_clock;

namespace {

// What the browsers are sent. Frames: only the newest one, numbered; a browser that lags skips
// frames. Maps: a browser first gets the whole map (encoder.full()), then the numbered changes
// (map_delta.hpp) in order; the last kMapDeltasKept of them are kept, and a browser that lags
// further behind gets the whole map again. Readers (one per browser) wait for what they have not
// been sent; writers never wait for readers.
class Outbox {
 public:
  enum Kind { kFrame, kMap };
  static constexpr std::size_t kMapDeltasKept = 32;  // 6 s at 5 map messages a second
  struct Seen {
    std::uint64_t frame = 0, map = 0;  // map: the last map message applied (0: an empty scene)
  };

  explicit Outbox(const MapDeltaEncoder& encoder) : encoder_(encoder) {}

  void publishFrame(std::string message) {
    auto shared = std::make_shared<const std::string>(std::move(message));
    {
      std::lock_guard lock(mutex_);
      frame_ = std::move(shared);
      ++frameSerial_;
      frameTaken_ = false;
    }
    changed_.notify_all();
  }
  void publishMap(MapDeltaEncoder::Message delta) {
    auto shared = std::make_shared<const std::string>(std::move(delta.json));
    {
      std::lock_guard lock(mutex_);
      mapDeltas_.emplace_back(delta.seq, std::move(shared));
      if (mapDeltas_.size() > kMapDeltasKept) mapDeltas_.pop_front();
      newestMap_ = std::max(newestMap_, delta.seq);
    }
    changed_.notify_all();
  }
  // Whether a browser has been handed the newest frame (true before the first): while it has
  // not, building a newer one would only be thrown away.
  bool frameTaken() const {
    std::lock_guard lock(mutex_);
    return frameTaken_;
  }
  // Waits up to `timeout` for a frame or map message this browser has not been sent; returns it
  // (or null) and updates `seen`.
  std::shared_ptr<const std::string> next(Seen& seen, Kind& kind, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, timeout,
                      [&] { return frameSerial_ > seen.frame || newestMap_ > seen.map || closed_; });
    if (frameSerial_ > seen.frame) {
      seen.frame = frameSerial_;
      frameTaken_ = true;
      kind = kFrame;
      return frame_;
    }
    if (newestMap_ <= seen.map) return nullptr;
    kind = kMap;
    if (seen.map > 0)  // a page that has a map: the next change, while it is kept
      for (const auto& [seq, message] : mapDeltas_)
        if (seq == seen.map + 1) {
          seen.map = seq;
          return message;
        }
    lock.unlock();  // the encoder has its own lock; building the whole map takes a while
    MapDeltaEncoder::Message whole = encoder_.full();
    seen.map = whole.seq;
    return std::make_shared<const std::string>(std::move(whole.json));
  }
  void close() {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
    }
    changed_.notify_all();
  }
  bool closed() const {
    std::lock_guard lock(mutex_);
    return closed_;
  }

 private:
  const MapDeltaEncoder& encoder_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::shared_ptr<const std::string> frame_;
  std::uint64_t frameSerial_ = 0;
  bool frameTaken_ = true;
  std::deque<std::pair<std::uint64_t, std::shared_ptr<const std::string>>> mapDeltas_;
  std::uint64_t newestMap_ = 0;
  bool closed_ = false;
};

}  // namespace

struct LiveViewer::Impl {
  ViewerOptions options;
  httplib::Server server;
  std::thread serverThread, publisherThread;
  MapDeltaEncoder mapEncoder;
  Outbox messages{mapEncoder};
  std::atomic<int> clients{0};

  std::mutex mutex;  // guards the fields below
  std::condition_variable wake;
  std::optional<FrameSnapshot> pendingFrame;
  RecentTimings recentTimings;       // of every frame, for the medians the page shows
  std::vector<MapPointId> localMap;  // of the newest frame
  bool stopping = false;
  std::mutex sourceMutex;  // held while a snapshot is taken: detach() waits for it, onFrame() never
  MapSnapshotSource source;

  std::mutex statsMutex;
  ViewerStats stats;

  void countMessage(bool map, std::size_t bytes);
  void serveRoutes();
  void streamEvents(httplib::Response& response);
  void publishLoop();
  void publishMap(const MapSnapshot& map, bool live);
  std::string frameMessageOf(FrameSnapshot& frame, const FrameTimingMedians& medians) const;
};

// The frame's message with its image; the image reference is let go here, on this thread.
std::string LiveViewer::Impl::frameMessageOf(FrameSnapshot& frame, const FrameTimingMedians& medians) const {
  const std::string jpeg = jpegBase64(frame.image, options.imageMaxWidth, options.jpegQuality);
  frame.image.release();
  return frameMessage(frame, jpeg, medians);
}

void LiveViewer::Impl::serveRoutes() {
  // First: the files' pattern below would match it too.
  server.Get("/events", [this](const httplib::Request&, httplib::Response& response) { streamEvents(response); });
  server.Get(R"(/(|[A-Za-z0-9_.\-]+))", [](const httplib::Request& request, httplib::Response& response) {
    const WebAsset* asset = webAsset(request.path);
    if (!asset) {
      response.status = 404;
      return;
    }
    // Straight from the embedded bytes, uncompressed: httplib would brotli-compress a body (850 kB
    // of three.js) on every request, on the machine that runs SLAM.
    response.set_content_provider(
        asset->size, std::string(asset->contentType),
        [asset](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
          return sink.write(reinterpret_cast<const char*>(asset->data) + offset, length);
        },
        [](bool) {});
  });
}

void LiveViewer::Impl::streamEvents(httplib::Response& response) {
  response.set_header("Cache-Control", "no-cache");
  ++clients;
  wake.notify_all();  // a new browser wants the current map now
  auto seen = std::make_shared<Outbox::Seen>();  // a new page starts from an empty scene
  response.set_chunked_content_provider(
      "text/event-stream",
      [this, seen](std::size_t, httplib::DataSink& sink) {
        Outbox::Kind kind{};
        auto message = messages.next(*seen, kind, std::chrono::milliseconds(500));
        if (messages.closed()) return false;
        std::string event = message ? std::string("event: ") + (kind == Outbox::kFrame ? "frame" : "map") +
                                          "\ndata: " + *message + "\n\n"
                                    : std::string(": keep-alive\n\n");
        return sink.write(event.data(), event.size());
      },
      [this](bool) { --clients; });
}

// The viewer is best-effort work on the machine that runs SLAM: its threads take the lowest
// priority (nice 19), so where tracking and mapping keep the cores busy they get only what SLAM
// leaves. Linux keeps a nice value per thread, and a thread's children start with it: called
// first on the server's thread, it covers the workers cpp-httplib starts there. Best effort: a
// refusal leaves the thread as it was.
namespace {
void yieldToSlam() {
#ifdef __linux__
  setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 19);
#endif
}
}  // namespace

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void LiveViewer::Impl::countMessage(bool map, std::size_t bytes) {
  std::lock_guard lock(statsMutex);
  ++(map ? stats.mapMessages : stats.frameMessages);
  stats.bytes += bytes;
}

void LiveViewer::Impl::publishMap(const MapSnapshot& map, bool live) {
  std::unordered_set<MapPointId> local;
  {
    std::lock_guard lock(mutex);
    local.insert(localMap.begin(), localMap.end());
  }
  MapDeltaEncoder::Message delta = mapEncoder.encode(map, local, live);
  countMessage(true, delta.json.size());
  messages.publishMap(std::move(delta));
}

void LiveViewer::Impl::publishLoop() {
  const auto framePeriod = std::chrono::duration<double>(1.0 / options.frameRateHz);
  const auto mapPeriod = std::chrono::duration<double>(1.0 / options.mapRateHz);
  Clock::time_point lastFrame{}, lastMap{};
  int clientsAtLastMap = 0;
  std::unique_lock lock(mutex);
  while (!stopping) {
    wake.wait_for(lock, std::chrono::duration_cast<Clock::duration>(framePeriod));
    if (stopping) break;
    const Clock::time_point now = Clock::now();
    if (clients == 0) continue;  // nobody watching: no work at all
    // A browser that has not yet been sent the last frame is slow: its frames wait (and are
    // replaced by newer ones) instead of being encoded for nothing.
    if (pendingFrame && now - lastFrame >= framePeriod && messages.frameTaken()) {
      FrameSnapshot frame = std::move(*pendingFrame);
      pendingFrame.reset();
      localMap = std::move(frame.localMapPoints);
      const FrameTimingMedians medians = recentTimings.medians();
      lock.unlock();
      std::string message = frameMessageOf(frame, medians);
      countMessage(false, message.size());
      messages.publishFrame(std::move(message));
      lock.lock();
      lastFrame = now;
    }
    const bool newClient = clients > clientsAtLastMap;
    if (now - lastMap >= mapPeriod || newClient) {
      lock.unlock();
      {
        std::lock_guard sourceLock(sourceMutex);
        if (source) publishMap(source(), true);
      }
      lock.lock();
      lastMap = now;
    }
    clientsAtLastMap = clients;
    std::lock_guard statsLock(statsMutex);
    stats.publisherCpuSeconds = threadCpuSeconds();
  }
}

LiveViewer::LiveViewer(ViewerOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  impl_->serveRoutes();
  // httplib's default adds SO_REUSEPORT, which lets a second viewer share a busy port silently.
  impl_->server.set_socket_options([](socket_t socket) {
    int yes = 1;
    setsockopt(socket, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  if (!impl_->server.bind_to_port(impl_->options.host.c_str(), impl_->options.port))
    throw Error("viewer", "", "cannot listen on " + url() + " (port in use?)");
  impl_->serverThread = std::thread([this] {
    nameThisThread("orbis-viewer");
    yieldToSlam();
    impl_->server.listen_after_bind();
  });
  impl_->publisherThread = std::thread([this] {
    nameThisThread("orbis-publisher");
    yieldToSlam();
    impl_->publishLoop();
  });
}

LiveViewer::~LiveViewer() {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->stopping = true;
  }
  impl_->wake.notify_all();
  impl_->messages.close();
  impl_->server.stop();
  if (impl_->publisherThread.joinable()) impl_->publisherThread.join();
  if (impl_->serverThread.joinable()) impl_->serverThread.join();
}

std::string LiveViewer::url() const {
  return "http://" + impl_->options.host + ":" + std::to_string(impl_->options.port) + "/";
}

ViewerStats LiveViewer::stats() const {
  std::lock_guard lock(impl_->statsMutex);
  return impl_->stats;
}

void LiveViewer::attach(MapSnapshotSource source) {
  std::lock_guard lock(impl_->sourceMutex);
  impl_->source = std::move(source);
}

void LiveViewer::onFrame(FrameSnapshot&& frame) {
  std::optional<FrameSnapshot> dropped;  // freed outside the lock
  {
    std::lock_guard lock(impl_->mutex);
    dropped.swap(impl_->pendingFrame);
    impl_->recentTimings.add(frame.extractionMs, frame.trackingMs);
    impl_->pendingFrame.emplace(std::move(frame));
  }
}

void LiveViewer::detach(MapSnapshot finalMap) {
  {
    std::lock_guard sourceLock(impl_->sourceMutex);  // a snapshot being taken finishes first
    impl_->source = nullptr;
  }
  {
    std::lock_guard lock(impl_->mutex);
    if (impl_->pendingFrame) {
      impl_->localMap = std::move(impl_->pendingFrame->localMapPoints);
      impl_->messages.publishFrame(
          impl_->frameMessageOf(*impl_->pendingFrame, impl_->recentTimings.medians()));
      impl_->pendingFrame.reset();
    }
  }
  impl_->publishMap(finalMap, false);
}

void LiveViewer::show(MapSnapshot map) { impl_->publishMap(map, false); }

}  // namespace orbis
