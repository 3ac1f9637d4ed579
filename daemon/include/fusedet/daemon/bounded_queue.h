// SPDX-License-Identifier: Apache-2.0
#pragma once
// BoundedQueue: a small multi-producer, single-consumer queue between pipeline threads. push()
// never blocks: when the queue is full the OLDEST item is dropped and counted, because for a robot
// the newest sensor data is the valuable one and a driver thread must never wait on a consumer.
// A producer that may wait (a log replayed as fast as possible, where nothing is lost by waiting)
// uses waitForRoom() first.
// Bounded by count and, with a size function, by bytes too: 512 sensor messages are little for
// laser scans but 2 GB of 1080p camera frames. The newest item always stays, even alone over
// the byte budget.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>

namespace fusedet::daemon {

struct QueueCounters {
  std::uint64_t pushed = 0;
  std::uint64_t dropped = 0;  // oldest items discarded because the queue was full
  std::size_t depth = 0;
  std::size_t bytes = 0;      // queued now, by the size function (0 without one)
};

template <class T>
class BoundedQueue {
 public:
  using SizeOf = std::function<std::size_t(const T&)>;
  // maxBytes 0 (or no sizeOf): bounded by count only.
  explicit BoundedQueue(std::size_t capacity, std::size_t maxBytes = 0, SizeOf sizeOf = {})
      : capacity_(capacity ? capacity : 1), maxBytes_(sizeOf ? maxBytes : 0), sizeOf_(std::move(sizeOf)) {}

  // Never blocks. Returns false if the push dropped an older item (or the queue is closed).
  bool push(T item) {
    bool dropped = false;
    {
      std::lock_guard lock(mutex_);
      if (closed_) return false;
      const std::size_t size = maxBytes_ ? sizeOf_(item) : 0;
      while (!items_.empty() && (items_.size() >= capacity_ || (maxBytes_ && bytes_ + size > maxBytes_))) {
        popFront();
        ++counters_.dropped;
        dropped = true;
      }
      items_.push_back({std::move(item), size});
      bytes_ += size;
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
      item = std::move(items_.front().item);
      popFront();
    }
    room_.notify_all();
    return item;
  }

  // Waits up to `timeout` until at most `maxDepth` items are queued and, with a byte budget, at
  // most half of it is used (or the queue is closed). True when there is that much room.
  bool waitForRoom(std::size_t maxDepth, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return room_.wait_for(lock, timeout, [&] {
      return closed_ || (items_.size() <= maxDepth && (!maxBytes_ || bytes_ <= maxBytes_ / 2));
    }) && !closed_;
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
    c.bytes = bytes_;
    return c;
  }

  std::size_t capacity() const { return capacity_; }
  std::size_t maxBytes() const { return maxBytes_; }

 private:
  struct Entry {
    T item;
    std::size_t bytes;
  };
  void popFront() {
    bytes_ -= items_.front().bytes;
    items_.pop_front();
  }

  const std::size_t capacity_;
  const std::size_t maxBytes_;
  const SizeOf sizeOf_;
  mutable std::mutex mutex_;
  std::condition_variable ready_, room_;
  std::deque<Entry> items_;
  std::size_t bytes_ = 0;
  QueueCounters counters_;
  bool closed_ = false;
};

}  // namespace fusedet::daemon
