#pragma once
// BoundedQueue: a small multi-producer, single-consumer queue between pipeline threads. push()
// never blocks: when the queue is full the OLDEST item is dropped and counted, because for a robot
// the newest sensor data is the valuable one and a driver thread must never wait on a consumer.
// A producer that may wait (a log replayed as fast as possible, where nothing is lost by waiting)
// uses waitForRoom() first.

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
    std::optional<T> item;
    {
      std::unique_lock lock(mutex_);
      ready_.wait_for(lock, timeout, [this] { return closed_ || !items_.empty(); });
      if (items_.empty()) return std::nullopt;
      item = std::move(items_.front());
      items_.pop_front();
    }
    room_.notify_all();
    return item;
  }

  // Waits up to `timeout` until at most `maxDepth` items are queued (or the queue is closed).
  // True when there is that much room.
  bool waitForRoom(std::size_t maxDepth, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return room_.wait_for(lock, timeout, [&] { return closed_ || items_.size() <= maxDepth; }) && !closed_;
  }

  // Wakes the consumer; later pushes are refused, queued items can still be popped.
  void close() {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
    room_.notify_all();
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
  std::condition_variable ready_, room_;
  std::deque<T> items_;
  QueueCounters counters_;
  bool closed_ = false;
};

}  // namespace fusedet::daemon
