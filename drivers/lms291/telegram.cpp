// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/lms291/telegram.h"

#include <algorithm>

namespace fusedet::drivers::lms291 {

std::uint16_t crc16(std::span<const std::uint8_t> bytes) {
  std::uint16_t crc = 0;
  std::uint8_t prev = 0;
  for (std::uint8_t b : bytes) {
    const bool carry = (crc & 0x8000u) != 0;
    crc = static_cast<std::uint16_t>(crc << 1);
    if (carry) crc ^= 0x8005u;
    crc ^= static_cast<std::uint16_t>((prev << 8) | b);
    prev = b;
  }
  return crc;
}

std::vector<std::uint8_t> encode(const Telegram& t) {
  const std::size_t length = 1 + t.data.size() + (t.status ? 1 : 0);
  std::vector<std::uint8_t> out;
  out.reserve(length + kFrameOverhead);
  out.push_back(kStx);
  out.push_back(t.address);
  out.push_back(static_cast<std::uint8_t>(length & 0xFF));
  out.push_back(static_cast<std::uint8_t>(length >> 8));
  out.push_back(t.command);
  out.insert(out.end(), t.data.begin(), t.data.end());
  if (t.status) out.push_back(*t.status);
  const std::uint16_t crc = crc16(out);
  out.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  out.push_back(static_cast<std::uint8_t>(crc >> 8));
  return out;
}

std::vector<std::uint8_t> encodeRequest(std::uint8_t command, std::span<const std::uint8_t> data) {
  Telegram t;
  t.address = kHostAddress;
  t.command = command;
  t.data.assign(data.begin(), data.end());
  return encode(t);
}

void TelegramReader::feed(std::span<const std::uint8_t> bytes, Stamp received) {
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
  counters_.bytes += bytes.size();
  lastFeed_ = received;
  if (!bytes.empty()) chunks_.emplace_back(bufferOffset_ + buffer_.size(), received);
}

Stamp TelegramReader::arrival(std::size_t endOffset) {
  // Chunks wholly before the buffer are history; keep the rest (a failed long frame may look
  // ahead, then a shorter real one follows).
  while (!chunks_.empty() && chunks_.front().first <= bufferOffset_) chunks_.pop_front();
  for (const auto& [chunkEnd, stamp] : chunks_)
    if (chunkEnd >= endOffset) return stamp - static_cast<std::int64_t>(chunkEnd - endOffset) * byteNs_;
  return lastFeed_;
}

// A backlog (the reader fell behind, the kernel buffer held many telegrams) makes the per-byte
// estimate too early for later chunks: a telegram cannot end before the previous one ended
// plus its own line time, nor after the chunk holding it was read.
Stamp TelegramReader::telegramArrival(std::size_t endOffset, std::size_t frameSize) {
  Stamp readAt = lastFeed_;
  for (const auto& [chunkEnd, stamp] : chunks_)
    if (chunkEnd >= endOffset) {
      readAt = stamp;
      break;
    }
  Stamp t = arrival(endOffset);
  if (lastTelegramEnd_.ns != 0) t = std::max(t, lastTelegramEnd_ + static_cast<std::int64_t>(frameSize) * byteNs_);
  t = std::min(t, readAt);
  // When a backlog pushed the previous telegram up to this read's time, the read-time bound
  // would give this one the same stamp: order wins by a nanosecond, so stamps stay strictly
  // increasing (equal stamps would make two scans indistinguishable downstream).
  if (lastTelegramEnd_.ns != 0) t = std::max(t, lastTelegramEnd_ + std::int64_t{1});
  return t;
}

void TelegramReader::clear() {
  bufferOffset_ += buffer_.size();
  buffer_.clear();
  chunks_.clear();
  lastTelegramEnd_ = Stamp{};
  inGarbage_ = false;
  releaseLone_ = false;
}

void TelegramReader::skip(std::size_t n) {
  if (!inGarbage_) {
    ++counters_.resyncs;
    inGarbage_ = true;
  }
  counters_.skippedBytes += n;
  buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(n));
  bufferOffset_ += n;
}

// Header at buffer_[at]: STX, an address of the expected direction, a length that fits.
bool TelegramReader::plausibleHeader(std::size_t at, std::size_t* frameSize) const {
  const std::uint8_t address = buffer_[at + 1];
  const bool device = (address & kReplyAddressBit) != 0;
  if (direction_ == Direction::kFromDevice && !device) return false;
  if (direction_ == Direction::kFromHost && address != kHostAddress) return false;
  const std::size_t length = buffer_[at + 2] | (std::size_t{buffer_[at + 3]} << 8);
  const std::size_t minLength = device ? 2 : 1;  // CMD (+ STATUS)
  if (length < minLength || length > kMaxLength) return false;
  *frameSize = length + kFrameOverhead;
  return true;
}

std::optional<StreamEvent> TelegramReader::next() {
  while (!buffer_.empty()) {
    const std::uint8_t b = buffer_.front();
    if (b == kAck || b == kNak) {
      // A lone ACK/NAK stands between telegrams: next comes an STX or silence. Without that
      // context a 06/15 is most likely a data byte of a telegram we joined in the middle.
      if (buffer_.size() == 1 && !releaseLone_) return std::nullopt;
      if (buffer_.size() > 1 && buffer_[1] != kStx) {
        skip(1);
        continue;
      }
      releaseLone_ = false;
      StreamEvent e;
      e.kind = b == kAck ? StreamEvent::Kind::kAckByte : StreamEvent::Kind::kNakByte;
      e.offset = bufferOffset_;
      e.received = lastFeed_;
      ++(b == kAck ? counters_.acks : counters_.naks);
      buffer_.pop_front();
      ++bufferOffset_;
      inGarbage_ = false;
      return e;
    }
    if (b != kStx) {
      skip(1);
      continue;
    }
    if (buffer_.size() < 4) return std::nullopt;  // need the header to judge
    std::size_t frameSize = 0;
    if (!plausibleHeader(0, &frameSize)) {
      skip(1);
      continue;
    }
    if (buffer_.size() < frameSize) return std::nullopt;
    std::vector<std::uint8_t> raw(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(frameSize));
    const std::uint16_t sent = static_cast<std::uint16_t>(raw[frameSize - 2] | (raw[frameSize - 1] << 8));
    const bool ok = crc16(std::span(raw).first(frameSize - 2)) == sent;

    StreamEvent e;
    e.offset = bufferOffset_;
    e.received = ok ? telegramArrival(bufferOffset_ + frameSize, frameSize) : arrival(bufferOffset_ + frameSize);
    Telegram& t = e.telegram;
    t.address = raw[1];
    t.command = raw[4];
    const bool hasStatus = t.fromDevice();
    const std::size_t dataEnd = frameSize - 2 - (hasStatus ? 1 : 0);
    t.data.assign(raw.begin() + 5, raw.begin() + static_cast<std::ptrdiff_t>(dataEnd));
    if (hasStatus) t.status = raw[frameSize - 3];
    t.received = e.received;
    t.offset = bufferOffset_;
    e.raw = std::move(raw);
    if (ok) {
      e.kind = StreamEvent::Kind::kTelegram;
      ++counters_.telegrams;
      lastTelegramEnd_ = e.received;
      buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(frameSize));
      bufferOffset_ += frameSize;
      inGarbage_ = false;
    } else {
      // Only the STX goes: a corrupt LEN must not take the next good telegram with it.
      e.kind = StreamEvent::Kind::kBadCrc;
      ++counters_.crcErrors;
      skip(1);
    }
    return e;
  }
  return std::nullopt;
}

bool TelegramReader::expirePending() {
  if (buffer_.empty()) return false;
  if (buffer_.size() == 1 && (buffer_[0] == kAck || buffer_[0] == kNak) && !releaseLone_) {
    releaseLone_ = true;  // silence after it: a real ACK/NAK
    return true;
  }
  // Whatever is left cannot complete: drop its first byte and let next() rescan the rest.
  ++counters_.expired;
  skip(1);
  return true;
}

}  // namespace fusedet::drivers::lms291
