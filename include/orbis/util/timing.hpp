// orbis/util/timing.hpp — per-stage wall-clock statistics in the manner of the paper's Table IV.
//
// Contract: StageTimer records durations (ms) under stage names; summary() gives count, mean,
// median, p95 and max per stage, in the order stages were first recorded. Thread-safe: the
// tracking, local-mapping and loop-closing threads record into one instance. With events enabled
// (diagnosis: `orbis run --stats`), stages also log per-frame and per-keyframe counters as named
// values; disabled, event() is a no-op and callers skip building them (eventsEnabled()).
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace orbis {

// Statistics of one stage over a run, in milliseconds.
struct StageStats {
  // The stage's name, e.g. "tracking: ORB extraction".
  std::string stage;
  // How many times it ran.
  std::size_t count = 0;
  // @{
  // Mean, median, 95th percentile and largest duration, ms.
  double meanMs = 0, medianMs = 0, p95Ms = 0, maxMs = 0;
  // @}
};

// One logged event: what it is about ("frame", "keyframe") and its named values.
struct StageEvent {
  // @{
  // What the event is about ("frame", "keyframe") and its counters by name.
  std::string kind;
  std::vector<std::pair<std::string, double>> values;
  // @}
};

// Per-stage durations and, for diagnosis, per-frame and per-keyframe events; thread-safe.
class StageTimer {
 public:
  // @{
  // Turns event logging on or off (orbis run --stats), and asks whether it is on.
  void enableEvents(bool on) { eventsOn_ = on; }
  bool eventsEnabled() const { return eventsOn_; }
  // @}
  // Logs an event when events are on.
  void event(std::string kind, std::vector<std::pair<std::string, double>> values) {
    if (!eventsOn_) return;
    std::lock_guard lock(mutex_);
    events_.push_back({std::move(kind), std::move(values)});
  }
  // The events logged so far.
  std::vector<StageEvent> events() const {
    std::lock_guard lock(mutex_);
    return events_;
  }

  // Records one duration of a stage, ms.
  void record(const std::string& stage, double ms) {
    std::lock_guard lock(mutex_);
    for (auto& [name, samples] : stages_)
      if (name == stage) { samples.push_back(ms); return; }
    stages_.emplace_back(stage, std::vector<double>{ms});
  }

  // Count, mean, median, p95 and max per stage, in the order stages were first recorded.
  std::vector<StageStats> summary() const {
    std::lock_guard lock(mutex_);
    std::vector<StageStats> out;
    for (const auto& [name, samplesIn] : stages_) {
      std::vector<double> s = samplesIn;
      std::sort(s.begin(), s.end());
      StageStats st;
      st.stage = name;
      st.count = s.size();
      double sum = 0;
      for (double v : s) sum += v;
      st.meanMs = sum / static_cast<double>(s.size());
      st.medianMs = s.size() % 2 ? s[s.size() / 2] : 0.5 * (s[s.size() / 2 - 1] + s[s.size() / 2]);
      st.p95Ms = s[std::min(s.size() - 1, static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(s.size()))) - 1)];
      st.maxMs = s.back();
      out.push_back(st);
    }
    return out;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<std::pair<std::string, std::vector<double>>> stages_;
  std::atomic<bool> eventsOn_{false};
  std::vector<StageEvent> events_;
};

// Measures the scope it lives in and records it into a StageTimer (or nowhere, if null).
class ScopedStage {
 public:
  // Starts measuring; the destructor records the time into timer under stage.
  ScopedStage(StageTimer* timer, std::string stage)
      : timer_(timer), stage_(std::move(stage)), start_(std::chrono::steady_clock::now()) {}
  ~ScopedStage() {
    if (timer_)
      timer_->record(stage_, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count());
  }
  ScopedStage(const ScopedStage&) = delete;
  ScopedStage& operator=(const ScopedStage&) = delete;

 private:
  StageTimer* timer_;
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace orbis
