// SPDX-License-Identifier: Apache-2.0
// Protocol contents: baud codes and words, count word, telegram sizes per variant, status
// offsets, special distance codes, interlaced merging (§3, §4 of the fact sheet).

#include <gtest/gtest.h>

#include <random>

#include "fusedet/drivers/lms291/protocol.h"
#include "fusedet/drivers/lms291/scan_assembler.h"
#include "fusedet/drivers/lms291/telegram.h"

using namespace fusedet::drivers::lms291;

TEST(LmsProtocol, BaudModesAndStatusWords) {
  // §3: 42=9600, 41=19200, 40=38400, 48=500000; words 8067, 8033, 8019, 8001.
  EXPECT_EQ(static_cast<int>(*baudMode(9600)), 0x42);
  EXPECT_EQ(static_cast<int>(*baudMode(19200)), 0x41);
  EXPECT_EQ(static_cast<int>(*baudMode(38400)), 0x40);
  EXPECT_EQ(static_cast<int>(*baudMode(500000)), 0x48);
  EXPECT_FALSE(baudMode(115200));
  EXPECT_EQ(baudWord(9600), 0x8067);
  EXPECT_EQ(baudWord(19200), 0x8033);
  EXPECT_EQ(baudWord(38400), 0x8019);
  EXPECT_EQ(baudWord(500000), 0x8001);
  EXPECT_EQ(*baudOfWord(0x8019), 38400);
  EXPECT_EQ(*baudOfMode(0x48), 500000);
}

TEST(LmsProtocol, TelegramSizesPerVariant) {
  // §4: total length 2N+10: 181->372, 361->732, 101->212, 201->412, 401->812.
  const std::pair<Variant, std::size_t> cases[] = {
      {{180, 100}, 372}, {{180, 50}, 732}, {{100, 100}, 212}, {{100, 50}, 412}, {{100, 25}, 812}};
  for (const auto& [v, total] : cases) {
    ASSERT_TRUE(v.valid());
    Telegram t;
    t.address = 0x80;
    t.command = kMeasuredValues;
    MeasuredValues mv;
    mv.values.assign(static_cast<std::size_t>(v.beams()), 100);
    t.data = encodeMeasuredValues(mv);
    t.status = 0x10;
    EXPECT_EQ(encode(t).size(), total) << v.angleDeg << "/" << v.resolutionCdeg;
  }
  // FUS: 361 values -> LEN D6 02.
  Telegram t;
  t.address = 0x80;
  t.command = kMeasuredValues;
  MeasuredValues mv;
  mv.values.assign(361, 0);
  t.data = encodeMeasuredValues(mv);
  t.status = 0x10;
  const auto bytes = encode(t);
  EXPECT_EQ(bytes[2], 0xD6);
  EXPECT_EQ(bytes[3], 0x02);
  EXPECT_FALSE((Variant{180, 25}.valid()));  // rejected by the device (§3)
  EXPECT_EQ((Variant{100, 25}.startDeg()), 40.0);
}

TEST(LmsProtocol, VariantRequestsMatchTheFactSheet) {
  // §3: angle 100/180 = 64 00 / B4 00; resolution 25/50/100 = 19 00 / 32 00 / 64 00; §1 vectors.
  EXPECT_EQ(variantPayload({100, 100}), (std::vector<std::uint8_t>{0x64, 0x00, 0x64, 0x00}));
  EXPECT_EQ(encodeRequest(0x3B, variantPayload({180, 50})),
            (std::vector<std::uint8_t>{0x02, 0x00, 0x05, 0x00, 0x3B, 0xB4, 0x00, 0x32, 0x00, 0x3B, 0x1F}));
  EXPECT_EQ(encodeRequest(0x3B, variantPayload({100, 25})),
            (std::vector<std::uint8_t>{0x02, 0x00, 0x05, 0x00, 0x3B, 0x64, 0x00, 0x19, 0x00, 0xE7, 0x72}));
  // Valid variants and their beam counts (§3): 181, 361, 101, 201, 401; 180/0.25 rejected.
  EXPECT_EQ((Variant{180, 100}.beams()), 181);
  EXPECT_EQ((Variant{180, 50}.beams()), 361);
  EXPECT_EQ((Variant{100, 100}.beams()), 101);
  EXPECT_EQ((Variant{100, 50}.beams()), 201);
  EXPECT_EQ((Variant{100, 25}.beams()), 401);
  EXPECT_FALSE((Variant{180, 25}.valid()));
  EXPECT_FALSE((Variant{90, 50}.valid()));
}

TEST(LmsProtocol, CountWordBits) {
  // bits 0-9 count, 11-12 partial index, 13 partial, 14-15 unit (01 = mm).
  const CountWord c = CountWord::decode(0x4169);  // 0100 0001 0110 1001: mm, count 361
  EXPECT_EQ(c.count, 361);
  EXPECT_EQ(c.unit, Unit::kMm);
  EXPECT_FALSE(c.partial);
  const CountWord p = CountWord::decode(0x2000 | 0x0800 | 181);  // partial, index 1, cm
  EXPECT_TRUE(p.partial);
  EXPECT_EQ(p.partialIndex, 1);
  EXPECT_EQ(p.count, 181);
  EXPECT_EQ(p.unit, Unit::kCm);
  EXPECT_EQ(CountWord::decode(0x7B45).encode(), 0x7B45);
}

TEST(LmsProtocol, MeasuredValuesWithAndWithoutRealTimeIndices) {
  const std::vector<std::uint8_t> plain{0x02, 0x40, 0x10, 0x27, 0xFF, 0x1F};  // mm, 2 values
  auto v = decodeMeasuredValues(plain);
  ASSERT_TRUE(v);
  EXPECT_EQ(v->values, (std::vector<std::uint16_t>{10000, 8191}));
  EXPECT_FALSE(v->telegramIndex);
  auto withIdx = plain;
  withIdx.push_back(7);
  withIdx.push_back(9);
  auto w = decodeMeasuredValues(withIdx);
  ASSERT_TRUE(w);
  EXPECT_EQ(*w->scanIndex, 7);
  EXPECT_EQ(*w->telegramIndex, 9);
  auto bad = plain;
  bad.push_back(1);
  auto b = decodeMeasuredValues(bad);
  ASSERT_FALSE(b);
  EXPECT_NE(b.error().message().find("count 2"), std::string::npos);
}

TEST(LmsProtocol, SpecialDistanceCodesAreNoReturn) {
  // §4: 8191 no value, 8190 dazzle, 8189 overflow, 8187, 8186, 8183 > max (13-bit modes).
  for (std::uint16_t code : {8191, 8190, 8189, 8187, 8186, 8183})
    EXPECT_EQ(valueToMeters(code, kMeasuring8m, Unit::kMm), 0.0f) << code;
  EXPECT_FLOAT_EQ(valueToMeters(8000, kMeasuring8m, Unit::kMm), 8.0f);
  EXPECT_FLOAT_EQ(valueToMeters(8000, kMeasuring8m, Unit::kCm), 80.0f);
  // Flag bits 13-15 are not distance in the 8/80 m modes.
  EXPECT_FLOAT_EQ(valueToMeters(0xE000 | 1234, kMeasuring8m, Unit::kMm), 1.234f);
  // 32 m mode: 15 bits (MRPT masks 0x7FFF in mm).
  EXPECT_FLOAT_EQ(valueToMeters(20000, kMeasuring32m, Unit::kMm), 20.0f);
  EXPECT_EQ(valueToMeters(32767, kMeasuring32m, Unit::kMm), 0.0f);
}

TEST(LmsProtocol, StatusOffsets) {
  // Offsets count the B1 byte as 0 (§3): 107 angle, 109 resolution, 116 baud, 122 unit.
  std::vector<std::uint8_t> data(151, 0);
  data[107 - 1] = 100;
  data[109 - 1] = 25;
  data[116 - 1] = 0x19;
  data[117 - 1] = 0x80;
  data[122 - 1] = 1;
  data[8 - 1] = 0x25;
  const char fw[] = "V02.06 ";
  for (int i = 0; i < 7; ++i) data[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(fw[i]);
  auto s = decodeStatus(data);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->angleDeg, 100);
  EXPECT_EQ(s->resolutionCdeg, 25);
  EXPECT_EQ(*s->baud, 38400);
  EXPECT_EQ(s->unit, Unit::kMm);
  EXPECT_EQ(s->operatingMode, 0x25);
  EXPECT_EQ(s->firmware, "V02.06 ");
  EXPECT_EQ(encodeStatus(*s), [&] {
    auto d = data;
    d[120 - 1] = 0;
    d[123 - 1] = 1;  // laser on
    return d;
  }());
  EXPECT_FALSE(decodeStatus(std::vector<std::uint8_t>(100, 0)));
}

TEST(LmsProtocol, StatusByteSeverityAndFlags) {
  EXPECT_FALSE(StatusByte{0x10}.needsAttention());  // what real units send normally
  const StatusByte s{0x82};
  EXPECT_EQ(s.severity(), 2);
  EXPECT_TRUE(s.pollution());
  EXPECT_TRUE(s.needsAttention());
  EXPECT_EQ(s.describe(), "warning, pollution");
  EXPECT_EQ(StatusByte{0x60}.describe(), "ok, restart, implausible values");
}

TEST(LmsProtocol, RangeRemissionRoundTripAndTruncation) {
  RemissionBlock b;
  b.start = 1;
  b.end = 3;
  b.countWord.unit = Unit::kMm;
  b.ranges = {1000, 2000, 3000};
  b.remissions = {10, 20, 30};
  const auto bytes = encodeRangeRemission(std::span(&b, 1));
  EXPECT_EQ(bytes.size(), 2u + 6u + 12u);
  auto d = decodeRangeRemission(bytes);
  ASSERT_TRUE(d);
  ASSERT_EQ(d->size(), 1u);
  EXPECT_EQ((*d)[0].ranges, b.ranges);
  EXPECT_EQ((*d)[0].remissions, b.remissions);
  EXPECT_EQ((*d)[0].countWord.unit, Unit::kMm);
  for (std::size_t cut = 0; cut < bytes.size(); ++cut)
    EXPECT_FALSE(decodeRangeRemission(std::span(bytes).first(cut))) << cut;
}

TEST(LmsScanAssembler, MergesInterlacedPartials) {
  // 100 deg / 0.25 deg: 4 rotations, partial indices 0..3, 401 beams (101+100+100+100).
  ScanAssembler a;
  a.reset(Variant{100, 25});
  EXPECT_EQ(a.partialSize(0), 101u);
  EXPECT_EQ(a.partialSize(3), 100u);
  std::optional<std::vector<std::uint16_t>> full;
  for (int k = 0; k < 4; ++k) {
    std::vector<std::uint16_t> part;
    for (std::size_t j = 0; j < a.partialSize(k); ++j) part.push_back(static_cast<std::uint16_t>(k + 4 * j));
    full = a.add(k, part);
    EXPECT_EQ(full.has_value(), k == 3);
  }
  ASSERT_TRUE(full);
  ASSERT_EQ(full->size(), 401u);
  for (std::size_t i = 0; i < 401; ++i) EXPECT_EQ((*full)[i], i);
}

TEST(LmsScanAssembler, DropsGroupsWithAMissingPartial) {
  // 180 deg / 0.5 deg: 2 rotations, partial indices 0 and 2 (0.25 deg steps).
  ScanAssembler a;
  a.reset(Variant{180, 50});
  const std::vector<std::uint16_t> p0(181, 1), p1(180, 2);
  EXPECT_FALSE(a.add(0, p0));
  EXPECT_TRUE(a.add(2, p1));
  EXPECT_FALSE(a.add(0, p0));
  EXPECT_FALSE(a.add(0, p0));  // second half lost: the first group is dropped
  EXPECT_EQ(a.droppedGroups(), 1u);
  EXPECT_TRUE(a.add(2, p1));
  EXPECT_FALSE(a.add(2, p1));  // orphan second half
  EXPECT_FALSE(a.add(1, p1));  // index 1 does not exist at 0.5 deg
  EXPECT_EQ(a.droppedGroups(), 2u);
  EXPECT_FALSE(a.add(0, std::vector<std::uint16_t>(10, 0)));  // wrong size
  EXPECT_EQ(a.droppedGroups(), 2u);
}

// Fuzz: every payload decoder on random and truncated input: errors, never crashes; whatever
// decodes re-encodes to the same bytes.
TEST(LmsProtocolFuzz, PayloadDecodersOnRandomBytes) {
  std::mt19937_64 rng(5);
  for (int iter = 0; iter < 20000; ++iter) {
    std::vector<std::uint8_t> d(rng() % 900);
    for (auto& b : d) b = static_cast<std::uint8_t>(rng());
    if (iter % 3 == 0 && d.size() >= 2) {  // plausible count words make it past the first check
      const std::size_t n = (d.size() - 2) / 2;
      d[0] = static_cast<std::uint8_t>(n & 0xFF);
      d[1] = static_cast<std::uint8_t>((d[1] & 0xFC) | ((n >> 8) & 0x3));
    }
    if (auto v = decodeMeasuredValues(d)) {
      EXPECT_EQ(encodeMeasuredValues(*v).size(), d.size());
    }
    if (auto r = decodeRangeRemission(d)) {
      EXPECT_EQ(encodeRangeRemission(*r).size(), d.size());
    }
    (void)decodeStatus(d);
    (void)decodeConfig(d);
  }
}
