#pragma once
// BoundedQueue: a small multi-producer, single-consumer queue between pipeline threads. push()
// never blocks: when the queue is full the OLDEST item is dropped and counted, because for a robot
// the newest sensor data is the valuable one and a driver thread must never wait on a consumer.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>

namespace fusedet::daemon {

struct QueueCounters {
  std::uint64_t pushed = 0;
  std::uint64_t dropped = 0;  // oldest items discarded because the queue was full
  std::size_t depth = 0;
};

template <class T>
class BoundedQueue {
 public:
  explicit BoundedQueue(std::size_t capacity) : capacity_(capacity ? capacity : 1) {}

  // Never blocks. Returns false if the push dropped an older item (or the queue is closed).
  bool push(T item) {
    bool dropped = false;
    {
      std::lock_guard lock(mutex_);
      if (closed_) return false;
      if (items_.size() >= capacity_) {
        items_.pop_front();
        ++counters_.dropped;
        dropped = true;
      }
      items_.push_back(std::move(item));
      ++counters_.pushed;
    }
    ready_.notify_one();
    return !dropped;
  }

  // Waits up to `timeout` for an item; nothing on timeout or when closed and empty.
  std::optional<T> pop(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    ready_.wait_for(lock, timeout, [this] { return closed_ || !items_.empty(); });
    if (items_.empty()) return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    return item;
  }

  // Wakes the consumer; later pushes are refused, queued items can still be popped.
  void close() {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

  bool closed() const {
    std::lock_guard lock(mutex_);
    return closed_;
  }

  QueueCounters counters() const {
    std::lock_guard lock(mutex_);
    QueueCounters c = counters_;
    c.depth = items_.size();
    return c;
  }

  std::size_t capacity() const { return capacity_; }

 private:
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<T> items_;
  QueueCounters counters_;
  bool closed_ = false;
};

}  // namespace fusedet::daemon
