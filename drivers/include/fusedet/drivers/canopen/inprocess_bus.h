// SPDX-License-Identifier: Apache-2.0
#pragma once
// InProcessBus: a CAN network inside one process, for tests and `fusedet tilt simulate`. Each
// connect() gives an Endpoint (a CanBus) that receives every frame the other endpoints send,
// like nodes on a wire (no loopback of its own frames). The bus stamps frames with its clock:
// Stamp::now() by default, or a simulated clock so tests run minutes of traffic in milliseconds
// and do not depend on machine load.

#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "fusedet/drivers/canopen/can_bus.h"

namespace fusedet::drivers::canopen {

class InProcessBus {
 public:
  class Endpoint;
  explicit InProcessBus(std::string name = "sim0", std::function<Stamp()> clock = {});
  InProcessBus(const InProcessBus&) = delete;
  InProcessBus& operator=(const InProcessBus&) = delete;

  // A new node on the bus. The bus must outlive its endpoints.
  std::unique_ptr<Endpoint> connect();
  Stamp now() const { return clock_ ? clock_() : Stamp::now(); }
  const std::string& name() const { return name_; }

 private:
  friend class Endpoint;
  void transmit(const Endpoint* from, const CanFrame& f);
  void detach(const Endpoint* e);

  std::string name_;
  std::function<Stamp()> clock_;
  std::mutex mutex_;  // guards endpoints_ (each endpoint guards its own queue)
  std::vector<Endpoint*> endpoints_;
};

class InProcessBus::Endpoint : public CanBus {
 public:
  explicit Endpoint(InProcessBus& bus) : bus_(bus) {}
  ~Endpoint() override;
  Result<void> send(const CanFrame& frame) override;
  Result<CanFrame> receive(std::chrono::microseconds timeout) override;
  Result<void> setFilters(const std::vector<CanFilter>& filters) override;
  Stamp now() const override { return bus_.now(); }
  CanBusCounters counters() const override;
  std::string name() const override { return bus_.name(); }

  // Fault injection: a bus-off controller neither sends (network_down) nor receives.
  void setBusOff(bool off);
  bool busOff() const;
  std::size_t pending() const;  // frames waiting in the receive queue

 private:
  friend class InProcessBus;
  void deliver(const CanFrame& f);  // called by the bus for frames of other endpoints

  InProcessBus& bus_;
  mutable std::mutex mutex_;
  std::condition_variable arrived_;
  std::deque<CanFrame> queue_;
  std::vector<CanFilter> filters_;
  bool busOff_ = false;
  CanBusCounters counters_;
  static constexpr std::size_t kQueueLimit = 4096;  // like a socket buffer: overflow drops frames
};

}  // namespace fusedet::drivers::canopen
