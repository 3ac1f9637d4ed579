// SPDX-License-Identifier: Apache-2.0
#pragma once
// Private: what the live server's sessions share - the stream type, the channels and limits, the
// viewers connected now (touched on the live thread only) and the counters (read by status from
// any thread).

#include <boost/asio/generic/stream_protocol.hpp>
#include <boost/beast/core/basic_stream.hpp>
#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

#include "fusedet/daemon/live/live_channels.h"
#include "fusedet/daemon/live/live_server.h"

namespace fusedet::daemon::live {

// TCP and Unix connections alike: the generic stream protocol carries either family.
using Protocol = boost::asio::generic::stream_protocol;
using Stream = boost::beast::basic_stream<Protocol>;

class ViewerSession;

struct LiveState {
  LiveState(LiveChannels c, LiveLimits l) : channels(std::move(c)), limits(l) { counters.encoded.resize(channels.channels().size()); }
  const LiveChannels channels;
  const LiveLimits limits;
  std::vector<std::shared_ptr<ViewerSession>> viewers;  // live thread only
  std::uint64_t nextViewer = 1;                         // live thread only
  // Some viewer subscribed to some channel: publish() returns at once while nobody did. Set by a
  // subscribe, recomputed by the live thread after each stack and once a second.
  std::atomic<bool> anySubscription{false};

  // Counters: each change under the lock.
  template <class F>
  void count(F&& f) {
    std::lock_guard lock(mutex);
    f(counters);
  }
  LiveCounters snapshot() const {
    std::lock_guard lock(mutex);
    LiveCounters c = counters;
    return c;
  }

 private:
  mutable std::mutex mutex;
  LiveCounters counters;
};

}  // namespace fusedet::daemon::live
