// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/canopen/inprocess_bus.h"

#include <algorithm>

namespace fusedet::drivers::canopen {

InProcessBus::InProcessBus(std::string name, std::function<Stamp()> clock)
    : name_(std::move(name)), clock_(std::move(clock)) {}

std::unique_ptr<InProcessBus::Endpoint> InProcessBus::connect() {
  auto e = std::make_unique<Endpoint>(*this);
  std::lock_guard lock(mutex_);
  endpoints_.push_back(e.get());
  return e;
}

void InProcessBus::transmit(const Endpoint* from, const CanFrame& f) {
  std::lock_guard lock(mutex_);
  for (Endpoint* e : endpoints_)
    if (e != from) e->deliver(f);
}

void InProcessBus::detach(const Endpoint* e) {
  std::lock_guard lock(mutex_);
  endpoints_.erase(std::remove(endpoints_.begin(), endpoints_.end(), e), endpoints_.end());
}

InProcessBus::Endpoint::~Endpoint() { bus_.detach(this); }

Result<void> InProcessBus::Endpoint::send(const CanFrame& frame) {
  if (frame.len > 8) return makeError(std::errc::invalid_argument, "send on " + name() + ": more than 8 data bytes");
  CanFrame f = frame;
  f.stamp = bus_.now();
  {
    std::lock_guard lock(mutex_);
    if (busOff_) {
      ++counters_.txFailures;
      return makeError(std::errc::network_down, "send on " + name() + ": bus-off");
    }
    ++counters_.framesTx;
  }
  notify(f, FrameDirection::kTx);
  bus_.transmit(this, f);
  return {};
}

void InProcessBus::Endpoint::deliver(const CanFrame& f) {
  std::lock_guard lock(mutex_);
  if (busOff_ || queue_.size() >= kQueueLimit) return;
  if (!f.error && !filters_.empty() &&
      std::none_of(filters_.begin(), filters_.end(), [&](const CanFilter& c) { return c.matches(f); }))
    return;
  queue_.push_back(f);
  arrived_.notify_one();
}

Result<CanFrame> InProcessBus::Endpoint::receive(std::chrono::microseconds timeout) {
  CanFrame f;
  {
    std::unique_lock lock(mutex_);
    if (!arrived_.wait_for(lock, timeout, [&] { return !queue_.empty(); })) {
      ++counters_.timeouts;
      return makeError(std::errc::timed_out, "receive on " + name());
    }
    f = queue_.front();
    queue_.pop_front();
    ++counters_.framesRx;
    if (f.error) ++counters_.errorFrames;
  }
  notify(f, FrameDirection::kRx);
  return f;
}

Result<void> InProcessBus::Endpoint::setFilters(const std::vector<CanFilter>& filters) {
  std::lock_guard lock(mutex_);
  filters_ = filters;
  return {};
}

CanBusCounters InProcessBus::Endpoint::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

void InProcessBus::Endpoint::setBusOff(bool off) {
  std::lock_guard lock(mutex_);
  busOff_ = off;
  if (off) queue_.clear();
}

bool InProcessBus::Endpoint::busOff() const {
  std::lock_guard lock(mutex_);
  return busOff_;
}

std::size_t InProcessBus::Endpoint::pending() const {
  std::lock_guard lock(mutex_);
  return queue_.size();
}

}  // namespace fusedet::drivers::canopen
