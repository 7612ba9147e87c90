// orbis/util/progress.hpp — a terminal progress bar for long work.
//
// Contract: draws to stderr only when stderr is a terminal (so logs and --json output stay
// clean); update() is cheap to call every item and redraws at most ~10 times per second.
// Without a total (0: a live stream), it is a status line: the count, the time and the status.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>
#include <unistd.h>

namespace orbis {

// A progress bar on standard error, drawn only on a terminal and at most ten times a second.
class ProgressBar {
 public:
  // label: what is counted; total: how many items make 100 %; enabled false: never draws.
  ProgressBar(std::string label, std::size_t total, bool enabled = true)
      : label_(std::move(label)), total_(total),
        enabled_(enabled && ::isatty(::fileno(stderr)) != 0),
        start_(std::chrono::steady_clock::now()) {}
  ~ProgressBar() { finish(); }

  // done: items completed so far; status: short free text shown after the bar (e.g. "OK 31 fps").
  void update(std::size_t done, const std::string& status = {}) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if ((total_ == 0 || done < total_) && now - lastDraw_ < std::chrono::milliseconds(100)) return;
    lastDraw_ = now;
    if (total_ == 0) {
      const double secs = std::chrono::duration<double>(now - start_).count();
      std::fprintf(stderr, "\r%s %zu frames %.1fs %s\x1b[K", label_.c_str(), done, secs, status.c_str());
      std::fflush(stderr);
      drawn_ = true;
      return;
    }
    const double frac = total_ ? static_cast<double>(done) / static_cast<double>(total_) : 1.0;
    const int width = 30;
    const int filled = static_cast<int>(frac * width + 0.5);
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.resize(width, '.');
    const double secs = std::chrono::duration<double>(now - start_).count();
    std::fprintf(stderr, "\r%s [%s] %zu/%zu %5.1f%% %.1fs %s\x1b[K", label_.c_str(), bar.c_str(),
                 done, total_, 100.0 * frac, secs, status.c_str());
    std::fflush(stderr);
    drawn_ = true;
  }
  // Whether the bar draws at all.
  bool enabled() const { return enabled_; }
  // Ends the bar's line (also done by the destructor).
  void finish() {
    if (enabled_ && drawn_) {
      std::fputc('\n', stderr);
      drawn_ = false;
    }
  }

 private:
  std::string label_;
  std::size_t total_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point lastDraw_{};
};

}  // namespace orbis
