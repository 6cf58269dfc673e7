// Progress lines on stderr, only when stderr is a terminal.
#pragma once

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <mutex>

#include <spdlog/sinks/base_sink.h>

namespace patrolmap::tools {

// Whether a progress line stands unfinished on stderr: a message logged then starts on a line of its own
// (ProgressAwareSink), never glued to it.
inline std::atomic<bool>& ProgressLineOpen() {
  static std::atomic<bool> open{false};
  return open;
}

class Progress {
 public:
  explicit Progress(const char* what, const char* unit = "frames")
      : what_(what), unit_(unit), enabled_(::isatty(STDERR_FILENO) != 0) {}
  ~Progress() {
    if (enabled_ && ProgressLineOpen().exchange(false)) std::fprintf(stderr, "\n");
  }

  // Shows "what: done/total (rate/s)"; total < 0 when unknown. A count that goes down starts a new line (the
  // next of several logs).
  void Update(std::int64_t done, std::int64_t total) {
    if (!enabled_) return;
    if (done < last_done_) {
      if (ProgressLineOpen().exchange(false)) std::fprintf(stderr, "\n");
      start_ = std::chrono::steady_clock::now();
    }
    last_done_ = done;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double rate = seconds > 0.0 ? done / seconds : 0.0;
    if (total > 0) {
      std::fprintf(stderr, "\r%s: %lld/%lld %s (%.0f/s)   ", what_, static_cast<long long>(done),
                   static_cast<long long>(total), unit_, rate);
    } else {
      std::fprintf(stderr, "\r%s: %lld %s (%.0f/s)   ", what_, static_cast<long long>(done), unit_, rate);
    }
    ProgressLineOpen() = true;
  }

 private:
  const char* what_;
  const char* unit_;
  bool enabled_;
  std::int64_t last_done_ = 0;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// The messages' sink on stderr: ends an open progress line first.
class ProgressAwareSink : public spdlog::sinks::base_sink<std::mutex> {
 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    if (ProgressLineOpen().exchange(false)) std::fputc('\n', stderr);
    spdlog::memory_buf_t formatted;
    formatter_->format(message, formatted);
    std::fwrite(formatted.data(), 1, formatted.size(), stderr);
  }
  void flush_() override { std::fflush(stderr); }
};

}  // namespace patrolmap::tools
