// SPDX-License-Identifier: Apache-2.0
// Telegram layer: every vector of the protocol fact sheet (../shared/docs/lms291-protocol.md §1),
// the reader's framing, ACK/NAK and resynchronisation, and fuzz-style robustness.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "fusedet/drivers/lms291/protocol.h"
#include "fusedet/drivers/lms291/telegram.h"

using namespace fusedet::drivers::lms291;
using Bytes = std::vector<std::uint8_t>;

namespace {

Bytes cat(Bytes a, const std::string& s) {
  a.insert(a.end(), s.begin(), s.end());
  return a;
}
Bytes cat(Bytes a, const Bytes& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}
Bytes withCrc(const Bytes& frame) {
  const std::uint16_t c = crc16(frame);
  return cat(frame, Bytes{static_cast<std::uint8_t>(c & 0xFF), static_cast<std::uint8_t>(c >> 8)});
}

// (telegram without CRC, CRC bytes as sent) from the fact sheet, §1 "Vectors" and "Replies".
struct Vector {
  const char* what;
  Bytes body;
  Bytes crc;
};
std::vector<Vector> factSheetVectors() {
  return {
      {"status request (worked trace)", {0x02, 0x00, 0x01, 0x00, 0x31}, {0x15, 0x12}},
      {"start stream 20 24", {0x02, 0x00, 0x02, 0x00, 0x20, 0x24}, {0x34, 0x08}},
      {"stop stream 20 25", {0x02, 0x00, 0x02, 0x00, 0x20, 0x25}, {0x35, 0x08}},
      {"38400 baud 20 40", {0x02, 0x00, 0x02, 0x00, 0x20, 0x40}, {0x50, 0x08}},
      {"9600 baud 20 42", {0x02, 0x00, 0x02, 0x00, 0x20, 0x42}, {0x52, 0x08}},
      {"500k baud 20 48", {0x02, 0x00, 0x02, 0x00, 0x20, 0x48}, {0x58, 0x08}},
      {"one scan 30 01", {0x02, 0x00, 0x02, 0x00, 0x30, 0x01}, {0x31, 0x18}},
      {"installation mode", cat({0x02, 0x00, 0x0A, 0x00, 0x20, 0x00}, "SICK_LMS"), {0xBE, 0xC5}},
      {"variant 180/0.5", {0x02, 0x00, 0x05, 0x00, 0x3B, 0xB4, 0x00, 0x32, 0x00}, {0x3B, 0x1F}},
      {"variant 100/0.25", {0x02, 0x00, 0x05, 0x00, 0x3B, 0x64, 0x00, 0x19, 0x00}, {0xE7, 0x72}},
      {"type 3A", {0x02, 0x00, 0x01, 0x00, 0x3A}, {0x1E, 0x12}},
      {"read config 74", {0x02, 0x00, 0x01, 0x00, 0x74}, {0x50, 0x12}},
      {"45 01 00 (DTU)", {0x02, 0x00, 0x03, 0x00, 0x45, 0x01, 0x00}, {0xA6, 0xD2}},
      {"reply A0 00 10 addr 80", {0x02, 0x80, 0x03, 0x00, 0xA0, 0x00, 0x10}, {0x16, 0x0A}},
      {"reply A0 00 10 addr 81", {0x02, 0x81, 0x03, 0x00, 0xA0, 0x00, 0x10}, {0x36, 0x1A}},
      {"power-on 90", cat(cat({0x02, 0x81, 0x17, 0x00, 0x90}, "LMS200;301063;V02.06 "), Bytes{0x13}), {0x64, 0x5A}},
  };
}

}  // namespace

TEST(LmsCrc, WorkedTraceOfTheStatusRequest) {
  // §1: 02 00 01 00 31 runs through 0002 -> 0204 -> 0409 -> 0912 -> 1215.
  const Bytes t{0x02, 0x00, 0x01, 0x00, 0x31};
  const std::uint16_t expected[] = {0x0002, 0x0204, 0x0409, 0x0912, 0x1215};
  for (std::size_t n = 1; n <= t.size(); ++n)
    EXPECT_EQ(crc16(std::span(t).first(n)), expected[n - 1]) << "after " << n << " bytes";
}

TEST(LmsCrc, EveryFactSheetVector) {
  for (const Vector& v : factSheetVectors()) {
    const std::uint16_t c = crc16(v.body);
    EXPECT_EQ(c & 0xFF, v.crc[0]) << v.what;
    EXPECT_EQ(c >> 8, v.crc[1]) << v.what;
  }
}

// What the CRC cannot see (a property of the algorithm, found by the fuzz test below): one
// shift per byte plus the previous byte in the high half means that flipping bit b of byte i
// together with bit b+1 of byte i+1 (not the last byte) leaves the CRC unchanged. Single-byte errors are always
// detected. The driver therefore checks every scan's count, unit and length as well.
TEST(LmsCrc, BlindToPairedFlipsInNeighbouringBytes) {
  const Bytes t{0x02, 0x80, 0x0A, 0x00, 0xB0, 0x03, 0x40, 0xE8, 0x03, 0xD0, 0x07, 0xFF, 0x1F, 0x10};
  const std::uint16_t c = crc16(t);
  for (std::size_t i = 5; i + 2 < t.size(); ++i)  // byte i+1 must not be the last one
    for (int b = 0; b < 7; ++b) {
      Bytes m = t;
      m[i] ^= static_cast<std::uint8_t>(1u << b);
      EXPECT_NE(crc16(m), c) << "single flip at " << i;
      m[i + 1] ^= static_cast<std::uint8_t>(1u << (b + 1));
      EXPECT_EQ(crc16(m), c) << "paired flip at " << i << " bit " << b;
    }
}

TEST(LmsTelegram, EncoderReproducesTheRequestVectors) {
  EXPECT_EQ(encodeRequest(0x31), withCrc({0x02, 0x00, 0x01, 0x00, 0x31}));
  EXPECT_EQ(encodeRequest(0x31), (Bytes{0x02, 0x00, 0x01, 0x00, 0x31, 0x15, 0x12}));
  EXPECT_EQ(encodeRequest(0x20, Bytes{0x24}), (Bytes{0x02, 0x00, 0x02, 0x00, 0x20, 0x24, 0x34, 0x08}));
  EXPECT_EQ(encodeRequest(0x30, Bytes{0x01}), (Bytes{0x02, 0x00, 0x02, 0x00, 0x30, 0x01, 0x31, 0x18}));
  const std::string pw = "SICK_LMS";
  Bytes install{0x00};
  install.insert(install.end(), pw.begin(), pw.end());
  EXPECT_EQ(encodeRequest(0x20, install), cat(cat({0x02, 0x00, 0x0A, 0x00, 0x20, 0x00}, pw), Bytes{0xBE, 0xC5}));
  EXPECT_EQ(encodeRequest(0x3B, Bytes{0xB4, 0x00, 0x32, 0x00}),
            (Bytes{0x02, 0x00, 0x05, 0x00, 0x3B, 0xB4, 0x00, 0x32, 0x00, 0x3B, 0x1F}));
  EXPECT_EQ(encodeRequest(0x45, Bytes{0x01, 0x00}), (Bytes{0x02, 0x00, 0x03, 0x00, 0x45, 0x01, 0x00, 0xA6, 0xD2}));
}

TEST(LmsTelegram, ReaderDecodesEveryVectorInBothDirections) {
  for (const Vector& v : factSheetVectors()) {
    TelegramReader reader(Direction::kAny);
    reader.feed(cat(v.body, v.crc));
    auto e = reader.next();
    ASSERT_TRUE(e) << v.what;
    ASSERT_EQ(e->kind, StreamEvent::Kind::kTelegram) << v.what;
    EXPECT_EQ(e->telegram.command, v.body[4]) << v.what;
    EXPECT_EQ(e->telegram.address, v.body[1]) << v.what;
    // Re-encoding gives the same bytes back.
    EXPECT_EQ(encode(e->telegram), cat(v.body, v.crc)) << v.what;
  }
}

TEST(LmsTelegram, ReplyAfterAckAsFusSendsIt) {
  // §2: 06, then 02 80 03 00 A0 00 10 16 0A.
  TelegramReader reader;
  reader.feed(Bytes{0x06, 0x02, 0x80, 0x03, 0x00, 0xA0, 0x00, 0x10, 0x16, 0x0A});
  auto ack = reader.next();
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->kind, StreamEvent::Kind::kAckByte);
  auto t = reader.next();
  ASSERT_TRUE(t);
  ASSERT_EQ(t->kind, StreamEvent::Kind::kTelegram);
  EXPECT_EQ(t->telegram.command, 0xA0);
  EXPECT_EQ(t->telegram.data, Bytes{0x00});
  ASSERT_TRUE(t->telegram.status);
  EXPECT_EQ(*t->telegram.status, 0x10);
  EXPECT_FALSE(reader.next());
}

TEST(LmsTelegram, TelegramsEndingInsideAChunkAreStampedByLineTime) {
  const Bytes reply{0x02, 0x80, 0x03, 0x00, 0xA0, 0x00, 0x10, 0x16, 0x0A};
  TelegramReader reader;
  reader.setByteTime(20'000);  // 500 kbaud: 20 us per byte
  reader.feed(cat(reply, reply), fusedet::Stamp{1'000'000'000});
  auto first = reader.next();
  auto second = reader.next();
  ASSERT_TRUE(first && second);
  EXPECT_EQ(first->telegram.received.ns, 1'000'000'000 - 9 * 20'000);  // 9 bytes followed it
  EXPECT_EQ(second->telegram.received.ns, 1'000'000'000);
  reader.feed(Bytes(reply.begin(), reply.begin() + 4), fusedet::Stamp{2'000'000'000});
  reader.feed(Bytes(reply.begin() + 4, reply.end()), fusedet::Stamp{3'000'000'000});
  auto split = reader.next();
  ASSERT_TRUE(split);
  EXPECT_EQ(split->telegram.received.ns, 3'000'000'000);
}

// A read that returns sooner after the previous one than its telegrams' line time (the kernel
// buffered them during a backlog): both bounds collide at the read time, and the stamps must
// still be strictly increasing so that two scans never share a stamp.
TEST(LmsTelegram, BackloggedTelegramsInOneReadKeepStrictlyIncreasingStamps) {
  const Bytes reply{0x02, 0x80, 0x03, 0x00, 0xA0, 0x00, 0x10, 0x16, 0x0A};
  TelegramReader reader;
  reader.setByteTime(20'000);
  reader.feed(reply, fusedet::Stamp{1'000'000'000});
  auto earlier = reader.next();
  ASSERT_TRUE(earlier);
  const fusedet::Stamp readAt{1'000'010'000};  // 10 us later, 18 bytes (360 us of line) in it
  reader.feed(cat(reply, reply), readAt);
  auto first = reader.next();
  auto second = reader.next();
  ASSERT_TRUE(first && second);
  EXPECT_GT(first->telegram.received, earlier->telegram.received);
  EXPECT_GT(second->telegram.received, first->telegram.received);
  EXPECT_LE(first->telegram.received, readAt);
  EXPECT_LE(second->telegram.received - readAt, 1);  // at most the tie-breaking nanosecond
}

TEST(LmsTelegram, PowerOnTelegramText) {
  TelegramReader reader;
  reader.feed(cat(cat(cat({0x02, 0x81, 0x17, 0x00, 0x90}, "LMS200;301063;V02.06 "), Bytes{0x13}), Bytes{0x64, 0x5A}));
  auto t = reader.next();
  ASSERT_TRUE(t);
  ASSERT_EQ(t->kind, StreamEvent::Kind::kTelegram);
  EXPECT_EQ(t->telegram.command, kPowerOnReply);
  EXPECT_EQ(std::string(t->telegram.data.begin(), t->telegram.data.end()), "LMS200;301063;V02.06 ");
  EXPECT_EQ(*t->telegram.status, 0x13);
  EXPECT_EQ(t->telegram.size(), 29u);
}

TEST(LmsTelegram, HostReaderRejectsDeviceTelegramsAndViceVersa) {
  const Bytes request = encodeRequest(0x31);
  const Bytes reply{0x02, 0x80, 0x03, 0x00, 0xA0, 0x00, 0x10, 0x16, 0x0A};
  TelegramReader fromDevice(Direction::kFromDevice);
  fromDevice.feed(request);
  while (auto e = fromDevice.next()) EXPECT_NE(e->kind, StreamEvent::Kind::kTelegram);
  EXPECT_EQ(fromDevice.counters().telegrams, 0u);
  TelegramReader fromHost(Direction::kFromHost);
  fromHost.feed(reply);
  while (auto e = fromHost.next()) EXPECT_NE(e->kind, StreamEvent::Kind::kTelegram);
  EXPECT_EQ(fromHost.counters().telegrams, 0u);
  EXPECT_GT(fromHost.counters().skippedBytes, 0u);
}

TEST(LmsTelegram, ResynchronisesAfterGarbageAndCorruptLength) {
  const Bytes good{0x02, 0x80, 0x03, 0x00, 0xA0, 0x00, 0x10, 0x16, 0x0A};
  // Garbage with a fake STX + address + a huge-but-legal length just before a good telegram:
  // the fake frame swallows the good one, fails its CRC, and the good one is found again.
  Bytes stream{0x55, 0xAA, 0x02, 0x80, 0x20, 0x03};
  stream = cat(stream, good);
  for (int i = 0; i < 800; ++i) stream.push_back(static_cast<std::uint8_t>(0x30 + i % 7));
  stream = cat(stream, good);
  TelegramReader reader;
  reader.feed(stream);
  int telegrams = 0;
  while (auto e = reader.next())
    if (e->kind == StreamEvent::Kind::kTelegram) ++telegrams;
  EXPECT_EQ(telegrams, 2);
  EXPECT_GE(reader.counters().crcErrors, 1u);
  EXPECT_GE(reader.counters().resyncs, 1u);
}

TEST(LmsTelegram, ExpireReleasesATelegramHeldByAFalseFrame) {
  const Bytes good{0x02, 0x80, 0x03, 0x00, 0xA0, 0x00, 0x10, 0x16, 0x0A};
  TelegramReader reader;
  reader.feed(cat(Bytes{0x02, 0x80, 0x00, 0x03}, good));  // fake frame of 768 bytes, then silence
  EXPECT_FALSE(reader.next());
  ASSERT_TRUE(reader.expirePending());
  auto e = reader.next();
  ASSERT_TRUE(e);
  EXPECT_EQ(e->kind, StreamEvent::Kind::kTelegram);
  EXPECT_EQ(e->telegram.command, 0xA0);
  EXPECT_EQ(reader.counters().expired, 1u);
}

TEST(LmsTelegram, SplitFeedsGiveTheSameTelegrams) {
  Bytes stream;
  for (int i = 0; i < 20; ++i) {
    Telegram t;
    t.address = 0x80;
    t.command = kMeasuredValues;
    MeasuredValues v;
    v.countWord.unit = Unit::kMm;
    for (int k = 0; k < 181; ++k) v.values.push_back(static_cast<std::uint16_t>(1000 + i * 7 + k));
    t.data = encodeMeasuredValues(v);
    t.status = 0x10;
    stream = cat(stream, encode(t));
    if (i % 3 == 0) stream.push_back(kAck);
  }
  std::mt19937 rng(7);
  TelegramReader reader;
  std::size_t at = 0;
  int telegrams = 0, acks = 0;
  while (at < stream.size()) {
    const std::size_t n = std::min<std::size_t>(stream.size() - at, 1 + rng() % 50);
    reader.feed(std::span(stream).subspan(at, n));
    at += n;
    while (auto e = reader.next()) {
      if (e->kind == StreamEvent::Kind::kTelegram) {
        auto v = decodeMeasuredValues(e->telegram.data);
        ASSERT_TRUE(v);
        EXPECT_EQ(v->values[0], 1000 + telegrams * 7);
        ++telegrams;
      }
      if (e->kind == StreamEvent::Kind::kAckByte) ++acks;
    }
  }
  EXPECT_EQ(telegrams, 20);
  EXPECT_EQ(acks, 7);
  EXPECT_EQ(reader.counters().resyncs, 0u);
}

// Fuzz: random bytes never crash the reader or the payload decoders, every telegram it
// reports really has a valid CRC, and it never holds more than one frame's worth of bytes.
TEST(LmsTelegramFuzz, RandomBytes) {
  std::mt19937_64 rng(1234);
  for (int iter = 0; iter < 300; ++iter) {
    TelegramReader reader(iter % 2 ? Direction::kAny : Direction::kFromDevice);
    for (int chunk = 0; chunk < 20; ++chunk) {
      Bytes b(rng() % 400);
      for (auto& x : b) x = static_cast<std::uint8_t>(rng() % 4 == 0 ? (rng() % 2 ? 0x02 : 0x80) : rng());
      reader.feed(b);
      while (auto e = reader.next()) {
        if (e->kind == StreamEvent::Kind::kTelegram) {
          const auto& raw = e->raw;
          ASSERT_GE(raw.size(), kFrameOverhead + 1);
          const std::uint16_t sent = static_cast<std::uint16_t>(raw[raw.size() - 2] | (raw[raw.size() - 1] << 8));
          EXPECT_EQ(crc16(std::span(raw).first(raw.size() - 2)), sent);
          (void)decodeMeasuredValues(e->telegram.data);
          (void)decodeRangeRemission(e->telegram.data);
          (void)decodeStatus(e->telegram.data);
          (void)decodeConfig(e->telegram.data);
        }
      }
      if (rng() % 5 == 0) reader.expirePending();
    }
  }
}

// Fuzz: mutate a clean stream of scans (flip, drop, insert bytes). Every telegram no mutation
// touched is still found, and nothing else is reported as a good telegram.
TEST(LmsTelegramFuzz, MutatedStreamsKeepEveryUntouchedTelegram) {
  std::mt19937_64 rng(99);
  int blindTotal = 0, damagedTotal = 0;
  for (int iter = 0; iter < 200; ++iter) {
    Bytes stream;
    std::vector<std::pair<std::size_t, std::size_t>> spans;  // [begin, end) of each telegram
    const int count = 30;
    for (int i = 0; i < count; ++i) {
      Telegram t;
      t.address = 0x80;
      t.command = kMeasuredValues;
      MeasuredValues v;
      v.countWord.unit = Unit::kMm;
      const int n = 20 + static_cast<int>(rng() % 200);
      for (int k = 0; k < n; ++k) v.values.push_back(static_cast<std::uint16_t>(rng() % 8192));
      v.values[0] = static_cast<std::uint16_t>(i);  // identity
      t.data = encodeMeasuredValues(v);
      t.status = 0x10;
      const Bytes e = encode(t);
      spans.emplace_back(stream.size(), stream.size() + e.size());
      stream = cat(stream, e);
    }
    std::vector<bool> touched(count, false);
    int blind = 0;
    Bytes mutated;
    for (std::size_t at = 0; at < stream.size(); ++at) {
      const int r = static_cast<int>(rng() % 1000);
      std::size_t which = 0;
      while (spans[which].second <= at) ++which;
      if (r < 3) {  // drop
        touched[which] = true;
        continue;
      }
      std::uint8_t b = stream[at];
      if (r < 6) {  // flip
        b ^= static_cast<std::uint8_t>(1u << (rng() % 8));
        touched[which] = true;
      }
      mutated.push_back(b);
      if (r >= 6 && r < 8 && at + 1 < stream.size() && spans[which].second == at + 1) {
        // garbage between telegrams
        for (int g = static_cast<int>(rng() % 12); g >= 0; --g) mutated.push_back(static_cast<std::uint8_t>(rng()));
      }
    }
    TelegramReader reader;
    std::vector<bool> found(count, false);
    std::size_t at = 0;
    while (at < mutated.size()) {
      const std::size_t n = std::min<std::size_t>(mutated.size() - at, 1 + rng() % 300);
      reader.feed(std::span(mutated).subspan(at, n));
      at += n;
      while (auto e = reader.next()) {
        if (e->kind != StreamEvent::Kind::kTelegram) continue;
        auto v = decodeMeasuredValues(e->telegram.data);
        ASSERT_TRUE(v) << "a good CRC over a malformed scan";
        ASSERT_LT(v->values[0], count);
        // The LMS CRC misses some multi-byte errors (e.g. bit b of byte i with bit b+1 of byte
        // i+1): such a frame is valid by definition. Anything else must be untouched.
        const bool crcBlind = touched[v->values[0]];
        if (crcBlind) ++blind;
        ASSERT_EQ(e->raw.size(), spans[v->values[0]].second - spans[v->values[0]].first);
        found[v->values[0]] = true;
      }
    }
    while (reader.expirePending()) {
      while (auto e = reader.next()) {
        if (e->kind != StreamEvent::Kind::kTelegram) continue;
        auto v = decodeMeasuredValues(e->telegram.data);
        if (v && v->values[0] < count) found[v->values[0]] = true;
      }
    }
    blindTotal += blind;
    damagedTotal += static_cast<int>(std::count(touched.begin(), touched.end(), true));
    for (int i = 0; i < count; ++i) {
      if (!touched[i]) {
        EXPECT_TRUE(found[i]) << "iteration " << iter << ": untouched telegram " << i << " lost";
      }
    }
  }
  // A few damaged frames in a thousand get through the CRC, never more.
  EXPECT_LT(blindTotal * 100, damagedTotal) << blindTotal << " of " << damagedTotal;
  std::printf("CRC-blind damaged telegrams: %d of %d\n", blindTotal, damagedTotal);
}
