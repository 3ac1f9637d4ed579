// SPDX-License-Identifier: Apache-2.0
#pragma once
// SICK LMS 2xx telegram layer: framing, the LMS CRC, and a byte-stream reader that finds
// telegrams and lone ACK/NAK bytes in a noisy serial stream and resynchronises after garbage.
//
// Frame: STX(0x02) ADDR LEN_lo LEN_hi CMD DATA... [STATUS] CRC_lo CRC_hi. LEN counts CMD + DATA
// (+ STATUS); the STATUS byte is present only in device->host telegrams (ADDR bit 7 set).

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <vector>

#include "fusedet/core/stamp.h"

namespace fusedet::drivers::lms291 {

inline constexpr std::uint8_t kStx = 0x02;
inline constexpr std::uint8_t kAck = 0x06;
inline constexpr std::uint8_t kNak = 0x15;
inline constexpr std::uint8_t kHostAddress = 0x00;   // host -> LMS
inline constexpr std::uint8_t kReplyAddressBit = 0x80;  // LMS -> host: 0x80 | unit address
inline constexpr std::size_t kFrameOverhead = 6;     // STX ADDR LEN LEN .. CRC CRC
// 812 bytes is the largest telegram (401 values); real-time indices add 2.
inline constexpr std::size_t kMaxTelegramSize = 814;
inline constexpr std::size_t kMaxLength = kMaxTelegramSize - kFrameOverhead;

// The LMS CRC: one shift per byte (not a standard CRC-16), polynomial 0x8005, init 0.
// It mixes in the previous byte, so flipping bit b of byte i together with bit b+1 of byte i+1
// leaves it unchanged (test LmsCrc.BlindToPairedFlipsInNeighbouringBytes): at 1 % single-bit
// flips per byte about 0.13 % of damaged 212-byte telegrams pass it (an independent C model).
// No driver can reject those; the simulator counts them (scansCrcBlind).
std::uint16_t crc16(std::span<const std::uint8_t> bytes);

struct Telegram {
  std::uint8_t address = kHostAddress;
  std::uint8_t command = 0;
  std::vector<std::uint8_t> data;      // after CMD, before STATUS
  std::optional<std::uint8_t> status;  // device replies only
  Stamp received;                      // when its last byte was read (reader output only)
  std::size_t offset = 0;              // stream offset of its STX (reader output only)

  bool fromDevice() const { return (address & kReplyAddressBit) != 0; }
  std::size_t size() const { return kFrameOverhead + 1 + data.size() + (status ? 1 : 0); }
};

// Encodes a telegram with its CRC (status is written when present).
std::vector<std::uint8_t> encode(const Telegram& t);
// Host -> LMS request: address 0, no status.
std::vector<std::uint8_t> encodeRequest(std::uint8_t command, std::span<const std::uint8_t> data = {});

// What the reader found in the stream.
struct StreamEvent {
  enum class Kind {
    kAckByte,     // lone 0x06 between telegrams (followed by STX or silence)
    kNakByte,     // lone 0x15 between telegrams (followed by STX or silence)
    kTelegram,  // a complete telegram with a valid CRC
    kBadCrc,    // a plausible frame whose CRC failed (raw bytes kept for diagnostics)
  };
  Kind kind = Kind::kTelegram;
  Telegram telegram;               // kTelegram, and kBadCrc (decoded as far as possible)
  std::vector<std::uint8_t> raw;   // kTelegram / kBadCrc: the frame bytes
  std::size_t offset = 0;          // stream offset of the byte/frame
  Stamp received;
};

struct ReaderCounters {
  std::uint64_t bytes = 0;      // bytes fed
  std::uint64_t telegrams = 0;  // valid telegrams
  std::uint64_t crcErrors = 0;  // frames whose CRC failed
  std::uint64_t resyncs = 0;    // runs of skipped (non-frame) bytes
  std::uint64_t skippedBytes = 0;
  std::uint64_t acks = 0;
  std::uint64_t naks = 0;
  std::uint64_t expired = 0;    // incomplete frames abandoned after a gap
};

// Which telegrams the reader accepts. The host reads device telegrams (ADDR bit 7 set, with
// status); the simulator reads host telegrams (ADDR 0, no status); a decoder accepts both and
// tells them apart by ADDR bit 7.
enum class Direction { kFromDevice, kFromHost, kAny };

// Incremental reader. On a CRC failure only the STX is dropped and the search restarts at the
// next byte, so a corrupt length field cannot swallow the good telegrams that follow.
class TelegramReader {
 public:
  explicit TelegramReader(Direction direction = Direction::kFromDevice) : direction_(direction) {}

  // `received`: when the chunk was read, i.e. when its last byte had arrived.
  void feed(std::span<const std::uint8_t> bytes, Stamp received = Stamp::now());
  // Line time of one byte: a telegram that ends inside a chunk is stamped that much earlier
  // per byte that followed it in the chunk (0 = stamp with the chunk's time).
  void setByteTime(std::int64_t ns) { byteNs_ = ns; }
  // Next event, or nothing when more bytes are needed.
  std::optional<StreamEvent> next();
  // After a silence: give up a frame that waits for bytes that will not come (e.g. a garbage
  // STX with a large "length"); the bytes after its STX are searched again. A trailing lone
  // ACK/NAK byte is released as such (next() waits for the byte after it, or this silence).
  // Returns true if anything was pending.
  bool expirePending();
  // Drop everything buffered (e.g. after a port re-open or a baud change).
  void clear();
  bool pending() const { return !buffer_.empty(); }

  const ReaderCounters& counters() const { return counters_; }

 private:
  bool plausibleHeader(std::size_t at, std::size_t* frameSize) const;
  void skip(std::size_t n);
  Stamp arrival(std::size_t endOffset);  // when the byte before stream offset endOffset arrived
  Stamp telegramArrival(std::size_t endOffset, std::size_t frameSize);

  Direction direction_;
  std::deque<std::uint8_t> buffer_;
  std::size_t bufferOffset_ = 0;  // stream offset of buffer_[0]
  Stamp lastFeed_;
  std::deque<std::pair<std::size_t, Stamp>> chunks_;  // (stream offset after the chunk, read time)
  std::int64_t byteNs_ = 0;
  Stamp lastTelegramEnd_;
  bool inGarbage_ = false;
  bool releaseLone_ = false;  // a trailing ACK/NAK byte was followed by silence
  ReaderCounters counters_;
};

}  // namespace fusedet::drivers::lms291
