// The capture thread and one-slot mailbox of a live source (frame_source.hpp: makeLiveSource).
#include <atomic>
#include <cstdio>
#include <utility>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "frame_source_common.hpp"
#include "orbis/adapters/frame_source.hpp"
#include "orbis/util/error.hpp"

namespace orbis {

namespace {

class LiveSource final : public FrameSource {
 public:
  LiveSource(std::unique_ptr<FrameSource> inner, bool pace, double stallSeconds)
      : inner_(std::move(inner)), pace_(pace), stall_(stallSeconds) {
    warnings_ = inner_->warnings();
    name_ = inner_->name();
  }
  ~LiveSource() override {
    stopping_ = true;
    slotChanged_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

  std::optional<SourceFrame> next() override {
    // Capture starts with the first request: frames are not dropped while the consumer sets up.
    if (!thread_.joinable()) thread_ = std::thread([this] { capture(); });
    std::unique_lock lock(mutex_);
    const auto giveUp = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                               std::chrono::duration<double>(stall_));
    while (!slot_ && !captureEnded_) {
      if (cancel_ && cancel_()) return std::nullopt;
      if (std::chrono::steady_clock::now() >= giveUp) {
        char seconds[32];
        std::snprintf(seconds, sizeof seconds, "%.1f", stall_);
        reason_ = name_ + " delivered no frame for " + seconds + " s";
        return std::nullopt;
      }
      slotChanged_.wait_for(lock, std::chrono::milliseconds(50));
    }
    if (!slot_) {
      if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
      return std::nullopt;
    }
    std::optional<SourceFrame> frame = std::move(slot_);
    slot_.reset();
    return frame;
  }

  std::string name() const override { return name_; }
  SensorKind sensor() const override { return inner_->sensor(); }
  bool live() const override { return true; }
  std::optional<std::size_t> expectedFrames() const override { return inner_->expectedFrames(); }
  const Trajectory& groundTruth() const override { return inner_->groundTruth(); }
  bool hasCalibration() const override { return inner_->hasCalibration(); }
  std::optional<DatasetCamera> camera() const override { return inner_->camera(); }
  RadTanDistortion<double> distortion() const override { return inner_->distortion(); }
  std::size_t dropped() const override { return dropped_.load(); }
  std::string endReason() const override {
    std::lock_guard lock(mutex_);
    return reason_;
  }

 private:
  // The capture thread: reads the inner source as fast as it delivers (or, paced, at its
  // timestamps) and overwrites the slot; the consumer takes whatever is newest.
  void capture() {
    std::optional<double> firstTimestamp;
    std::chrono::steady_clock::time_point firstFed;
    std::vector<std::string> pending;  // warnings of frames read but not delivered
    while (!stopping_) {
      std::optional<SourceFrame> frame;
      try {
        frame = inner_->next();
      } catch (const Error& e) {
        pending.push_back(e.what());  // one bad frame: reported on the next good one
        continue;
      } catch (...) {
        std::lock_guard lock(mutex_);
        failure_ = std::current_exception();
        break;
      }
      if (!frame) break;
      if (pace_) {
        const auto now = std::chrono::steady_clock::now();
        if (!firstTimestamp) {
          firstTimestamp = frame->timestamp;
          firstFed = now;
        } else {
          const auto due = firstFed + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                          std::chrono::duration<double>(frame->timestamp - *firstTimestamp));
          while (!stopping_ && std::chrono::steady_clock::now() < due)
            std::this_thread::sleep_until(std::min(due, std::chrono::steady_clock::now() + std::chrono::milliseconds(50)));
        }
      }
      frame->captured = std::chrono::steady_clock::now();
      std::lock_guard lock(mutex_);
      if (slot_) {
        ++dropped_;
        for (auto& w : slot_->warnings) pending.push_back(std::move(w));
      }
      for (auto& w : pending) frame->warnings.push_back(std::move(w));
      pending.clear();
      slot_ = std::move(frame);
      slotChanged_.notify_all();
    }
    std::lock_guard lock(mutex_);
    captureEnded_ = true;
    if (reason_.empty()) reason_ = inner_->endReason();
    slotChanged_.notify_all();
  }

  std::unique_ptr<FrameSource> inner_;
  bool pace_;
  double stall_;
  std::string name_;
  mutable std::mutex mutex_;
  std::condition_variable slotChanged_;
  std::optional<SourceFrame> slot_;
  bool captureEnded_ = false;
  std::exception_ptr failure_;
  std::string reason_;
  std::atomic<std::size_t> dropped_{0};
  std::atomic<bool> stopping_{false};
  std::thread thread_;  // started by the first next()
};

}  // namespace

std::unique_ptr<FrameSource> makeLiveSource(std::unique_ptr<FrameSource> source, bool paceByTimestamps, double stallSeconds) {
  if (source->live()) return source;
  return std::make_unique<LiveSource>(std::move(source), paceByTimestamps, stallSeconds);
}

}  // namespace orbis
