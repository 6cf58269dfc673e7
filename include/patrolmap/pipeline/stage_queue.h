// A stage of the per-frame pass behind a bounded queue (DESIGN.md, pipeline): its inputs are handled in the
// order they were pushed, on a worker thread or inline on the pushing thread. Either way the stage sees the
// same inputs in the same order, so its results do not depend on the threading.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

#include "patrolmap/core/status.h"

namespace patrolmap::pipeline {

struct StageQueueStats {
  int max_depth = 0;            // most inputs waiting at once
  double waited_seconds = 0.0;  // the pushing thread waiting for room
};

template <typename Input>
class StageQueue {
 public:
  using Handler = std::function<Status(Input&&)>;

  // `capacity` >= 1 inputs wait at most; the pushing thread waits when the queue is full.
  StageQueue(Handler handler, bool threaded, int capacity) : handler_(std::move(handler)), capacity_(capacity) {
    if (threaded) worker_ = std::thread(&StageQueue::Work, this);
  }
  ~StageQueue() { Close(); }
  StageQueue(const StageQueue&) = delete;
  StageQueue& operator=(const StageQueue&) = delete;

  // Hands `input` to the stage. Fails with the stage's first error (then nothing more is handled).
  Status Push(Input&& input) {
    if (!worker_.joinable()) {
      if (!status_.ok()) return status_;
      status_ = handler_(std::move(input));
      failed_.store(!status_.ok());
      return status_;
    }
    const auto start = std::chrono::steady_clock::now();
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return static_cast<int>(queue_.size()) < capacity_ || !status_.ok(); });
    stats_.waited_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!status_.ok()) return status_;
    queue_.push_back(std::move(input));
    stats_.max_depth = std::max(stats_.max_depth, static_cast<int>(queue_.size()));
    lock.unlock();
    changed_.notify_all();
    return Status::Ok();
  }

  // Whether the stage has failed, without taking the lock (cheap enough for every frame).
  bool failed() const { return failed_.load(); }

  // Lets the stage finish what is queued and stops the worker. Returns the stage's first error.
  Status Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closing_ = true;
    }
    changed_.notify_all();
    if (worker_.joinable()) worker_.join();
    return status_;
  }

  // Read after Close() (or from the pushing thread, which alone writes them).
  const StageQueueStats& stats() const { return stats_; }

 private:
  void Work() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (true) {
      changed_.wait(lock, [this] { return !queue_.empty() || closing_; });
      if (queue_.empty()) return;  // closing, and nothing left
      Input input = std::move(queue_.front());
      queue_.pop_front();
      const bool skip = !status_.ok();
      lock.unlock();
      const Status status = skip ? Status::Ok() : handler_(std::move(input));  // only this thread runs the stage
      lock.lock();
      if (!status.ok() && status_.ok()) {
        status_ = status;
        failed_.store(true);
      }
      changed_.notify_all();
    }
  }

  Handler handler_;
  int capacity_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Input> queue_;
  bool closing_ = false;
  Status status_;
  std::atomic<bool> failed_{false};
  StageQueueStats stats_;
  std::thread worker_;  // last: started once everything above exists
};

}  // namespace patrolmap::pipeline
