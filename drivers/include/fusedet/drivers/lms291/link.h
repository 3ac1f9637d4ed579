// SPDX-License-Identifier: Apache-2.0
#pragma once
// Link: the request/reply side of the telegram layer over a serial port. Sends a request,
// waits for the lone ACK (NAK => wait 30 ms and resend), then for the reply (request | 0x80),
// retrying on silence; while waiting, streamed telegrams are passed over and counted.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "fusedet/core/result.h"
#include "fusedet/drivers/lms291/protocol.h"
#include "fusedet/drivers/lms291/telegram.h"
#include "fusedet/drivers/serial_port.h"

namespace fusedet::drivers::lms291 {

// The LMS leaves at most 14 ms between the bytes of a telegram: a longer silence (at least 20 ms,
// or 20 byte times at slow speeds) means a pending "frame" was garbage and is given up.
inline std::chrono::microseconds silenceGap(int baud) {
  return std::chrono::microseconds(
      std::max<std::int64_t>(20'000, static_cast<std::int64_t>(byteSeconds(std::max(baud, 1)) * 1e6 * 20)));
}

struct LinkCounters {
  ReaderCounters reader;          // bytes, telegrams, CRC errors, resyncs, ACK/NAK bytes
  std::uint64_t requests = 0;
  std::uint64_t retries = 0;
  std::uint64_t timeouts = 0;     // ACK or reply missing, or no telegram within a read timeout
  std::uint64_t naks = 0;         // requests the device refused with NAK
  std::uint64_t passedOver = 0;   // telegrams that arrived while waiting for another reply
  std::uint64_t lateAnswers = 0;  // replies of a late device to copies of a request sent again
};

struct RequestOptions {
  std::chrono::milliseconds ackTimeout{100};     // device ACKs within 60 ms
  std::chrono::milliseconds replyTimeout{1000};  // after the ACK
  int retries = 3;
  bool acceptAnyTelegram = false;                // probing: any valid device telegram will do
};

class Link {
 public:
  Result<void> open(const std::string& path, int baud);
  void close();
  bool isOpen() const { return port_.isOpen(); }
  // Changes the host speed; drops what was buffered (it belonged to the old speed).
  Result<void> setBaud(int baud);
  int baud() const { return port_.baud(); }
  void setForceTermios2(bool force) { forceTermios2_ = force; }
  bool usedTermios2() const { return port_.usedTermios2(); }
  void flushInput();
  void drain() { port_.drain(); }

  // Sends `command data` and returns the reply telegram. Errors: timed_out (no ACK/reply
  // after all retries), operation_not_supported (0x92 reply), no_such_device (port gone).
  Result<Telegram> request(std::uint8_t command, std::span<const std::uint8_t> data, const RequestOptions& o);
  // Next valid device telegram; timed_out when none completes within `timeout`.
  Result<Telegram> receive(std::chrono::microseconds timeout);

  // While *cancel is true every wait ends at once with operation_canceled (prompt shutdown).
  void setCancelFlag(const std::atomic<bool>* cancel) { cancel_ = cancel; }

  // Sees every raw chunk read from the port (recording hook).
  void setRawHook(std::function<void(std::span<const std::uint8_t>, Stamp)> hook) { rawHook_ = std::move(hook); }

  LinkCounters counters() const;

 private:
  // Next stream event before `deadline`; an empty optional = deadline passed.
  Result<std::optional<StreamEvent>> nextEvent(std::chrono::steady_clock::time_point deadline);
  // After a reply: takes the answers of a late device to the copies sent at `copies` (retries).
  void takeLateAnswers(std::uint8_t expected, const std::vector<std::chrono::steady_clock::time_point>& copies,
                       const RequestOptions& o);

  SerialPort port_;
  TelegramReader reader_{Direction::kFromDevice};
  LinkCounters counters_;
  bool forceTermios2_ = false;
  const std::atomic<bool>* cancel_ = nullptr;
  std::function<void(std::span<const std::uint8_t>, Stamp)> rawHook_;
};

}  // namespace fusedet::drivers::lms291
