// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/lms291/link.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <thread>
#include <vector>

#include "fusedet/drivers/lms291/protocol.h"

#include <spdlog/spdlog.h>

namespace fusedet::drivers::lms291 {

namespace {
using Clock = std::chrono::steady_clock;
// After a NAK the device wants >= 30 ms before the request is sent again (§2).
constexpr auto kNakPause = std::chrono::milliseconds(30);
constexpr int kNakRetries = 3;
}  // namespace

Result<void> Link::open(const std::string& path, int baud) {
  auto port = SerialPort::open(path, baud);
  if (!port) return port.error();
  port_ = std::move(*port);
  reader_.clear();
  reader_.setByteTime(static_cast<std::int64_t>(byteSeconds(baud) * 1e9));
  if (forceTermios2_) return port_.setBaud(baud, true);
  return {};
}

void Link::close() {
  port_.close();
  reader_.clear();
}

Result<void> Link::setBaud(int baud) {
  auto r = port_.setBaud(baud, forceTermios2_);
  reader_.clear();
  reader_.setByteTime(static_cast<std::int64_t>(byteSeconds(baud) * 1e9));
  port_.flushInput();
  return r;
}

void Link::flushInput() {
  port_.flushInput();
  reader_.clear();
}

LinkCounters Link::counters() const {
  LinkCounters c = counters_;
  c.reader = reader_.counters();
  return c;
}

Result<std::optional<StreamEvent>> Link::nextEvent(Clock::time_point deadline) {
  const auto gap = silenceGap(port_.baud());
  std::array<std::uint8_t, 16384> buffer{};
  for (;;) {
    if (auto e = reader_.next()) return std::optional<StreamEvent>(std::move(*e));
    if (cancel_ && cancel_->load()) return makeError(std::errc::operation_canceled, "cancelled");
    // Past the deadline, what has already arrived still counts: a thread descheduled beyond its
    // deadline must not call a device late that answered in time. Only then is it a timeout.
    const auto now = Clock::now();
    const bool late = now >= deadline;
    const auto wait = late ? std::chrono::microseconds(0)
                           : std::min<std::chrono::microseconds>(
                                 gap, std::chrono::duration_cast<std::chrono::microseconds>(deadline - now));
    auto n = port_.read(buffer, wait);
    if (!n) return n.error();
    if (*n == 0) {
      if (late) return std::optional<StreamEvent>();
      if (wait == gap) reader_.expirePending();
      continue;
    }
    const Stamp stamp = Stamp::now();
    const std::span<const std::uint8_t> chunk(buffer.data(), *n);
    if (rawHook_) rawHook_(chunk, stamp);
    reader_.feed(chunk, stamp);
  }
}

Result<Telegram> Link::request(std::uint8_t command, std::span<const std::uint8_t> data, const RequestOptions& o) {
  const std::vector<std::uint8_t> bytes = encodeRequest(command, data);
  const std::uint8_t expected = command | kReplyBit;
  ++counters_.requests;
  // Silence uses up `retries`; a NAK proves the device is listening, so NAKs get their own
  // (bounded) budget: a probe without retries still survives a refused first request.
  int silentAttempts = 0, nakAttempts = 0;
  std::vector<Clock::time_point> silentSends;  // when the copies that met silence were sent
  for (int attempt = 0; silentAttempts <= o.retries && nakAttempts <= std::max(o.retries, kNakRetries); ++attempt) {
    if (attempt > 0) ++counters_.retries;
    // Line time of the request itself: at 9600 baud a long request takes tens of ms.
    const auto sendTime = std::chrono::microseconds(static_cast<std::int64_t>(byteSeconds(port_.baud()) * 1e6 * bytes.size()));
    const auto sentAt = Clock::now();
    if (auto w = port_.write(bytes, std::chrono::seconds(1) + sendTime); !w) return w.error();
    spdlog::trace("lms291 {}: sent 0x{:02X} ({} bytes) at {} baud, attempt {}", port_.path(), command, bytes.size(),
                  port_.baud(), attempt + 1);
    bool acked = false, nak = false;
    auto deadline = Clock::now() + o.ackTimeout + sendTime;
    for (;;) {
      auto ev = nextEvent(deadline);
      if (!ev) return ev.error();
      if (!*ev) {
        ++counters_.timeouts;
        ++silentAttempts;
        silentSends.push_back(sentAt);
        break;
      }
      const StreamEvent& e = **ev;
      spdlog::trace("lms291 {}: event {} cmd 0x{:02X} at offset {}", port_.path(), static_cast<int>(e.kind),
                    e.telegram.command, e.offset);
      if (e.kind == StreamEvent::Kind::kAckByte) {
        if (!acked) deadline = Clock::now() + o.replyTimeout;
        acked = true;
      } else if (e.kind == StreamEvent::Kind::kNakByte) {
        ++counters_.naks;
        ++nakAttempts;
        nak = true;
        break;
      } else if (e.kind == StreamEvent::Kind::kTelegram) {
        const std::uint8_t c = e.telegram.command;
        if (c == expected || o.acceptAnyTelegram) {
          if (c == expected && !silentSends.empty()) {
            silentSends.push_back(sentAt);
            takeLateAnswers(expected, silentSends, o);
          }
          return e.telegram;
        }
        if (c == kUnknownCommandReply)
        {
          char what[64];
          std::snprintf(what, sizeof what, "command 0x%02X refused as unknown (0x92)", command);
          return makeError(std::errc::operation_not_supported, what);
        }
        ++counters_.passedOver;
      }
      // kBadCrc: maybe our reply, maybe noise; keep waiting until the deadline.
    }
    if (nak) std::this_thread::sleep_for(kNakPause);
  }
  char what[128];
  std::snprintf(what, sizeof what, "no reply to command 0x%02X (%d silent, %d refused with NAK)", command,
                silentAttempts, nakAttempts);
  return makeError(std::errc::timed_out, what);
}

// A copy sent again after silence may have reached a device that was late, not deaf: it answers
// every copy (ACK, reply) in order. The answer just taken is then the first copy's, `latency`
// after it was sent, and the others follow like the copies were sent (`copies`: send times, the
// answered attempt last). They are taken here (counted lateAnswers), so that the next request with
// the same reply code does not mistake one for its own. A copy whose ACK has not come twice its
// latency after it was sent was lost (as are the copies after it): that costs one such wait.
void Link::takeLateAnswers(std::uint8_t expected, const std::vector<Clock::time_point>& copies, const RequestOptions& o) {
  const auto latency = std::max<Clock::duration>(Clock::now() - copies.front(), o.ackTimeout);
  for (std::size_t k = 1; k < copies.size(); ++k) {
    auto deadline = copies[k] + 2 * latency;
    bool acked = false;
    for (;;) {
      auto ev = nextEvent(deadline);
      if (!ev || !*ev) return;  // not answered: lost on the way, and so are the copies after it
      const StreamEvent& e = **ev;
      if (e.kind == StreamEvent::Kind::kNakByte) break;  // refused: no reply follows
      if (e.kind == StreamEvent::Kind::kAckByte && !acked) {
        acked = true;
        deadline = Clock::now() + o.replyTimeout;
      } else if (e.kind == StreamEvent::Kind::kTelegram) {
        if (e.telegram.command == expected) {
          ++counters_.lateAnswers;
          break;
        }
        ++counters_.passedOver;
      }
    }
  }
}

Result<Telegram> Link::receive(std::chrono::microseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    auto ev = nextEvent(deadline);
    if (!ev) return ev.error();
    if (!*ev) {
      ++counters_.timeouts;
      return makeError(std::errc::timed_out, "no telegram within " + std::to_string(timeout.count() / 1000) + " ms");
    }
    if ((*ev)->kind == StreamEvent::Kind::kTelegram) return std::move((*ev)->telegram);
  }
}

}  // namespace fusedet::drivers::lms291
