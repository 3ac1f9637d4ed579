// SPDX-License-Identifier: Apache-2.0
// MCAP writer and reader: round trip, chunking, time order, indexes and summary as bytes,
// damage (CRC, truncation at every offset), fuzzing. Expected values come from what the test
// wrote, and the summary layout is checked byte by byte against the spec's field order.

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

#include "../../process_temp_dir.h"
#include "fusedet/drivers/log/mcap_reader.h"
#include "fusedet/drivers/log/mcap_writer.h"

namespace fs = std::filesystem;
using namespace fusedet::drivers::mcap;

namespace {

fs::path tempFile(const std::string& name) {
  return fusedet::test::processTempDir() / name;
}

std::vector<std::uint8_t> readBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void writeBytes(const fs::path& p, std::span<const std::uint8_t> b) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}
std::vector<std::uint8_t> payload(int channel, int i) {
  const std::string s = "{\"c\":" + std::to_string(channel) + ",\"i\":" + std::to_string(i) + "}";
  return {s.begin(), s.end()};
}
std::uint64_t le64(const std::vector<std::uint8_t>& b, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(b[at + static_cast<std::size_t>(i)]) << (8 * i);
  return v;
}

// Two channels, interleaved out of order, small chunks: 200 + 100 messages.
fs::path writeSample(const std::string& name, WriterOptions o = {}) {
  const fs::path p = tempFile(name);
  o.chunkBytes = o.chunkBytes == WriterOptions{}.chunkBytes ? 2000 : o.chunkBytes;
  McapWriter w(p, o);
  const std::string schema = R"({"type":"object"})";
  const auto s = w.addSchema("test.A", "jsonschema", {reinterpret_cast<const std::uint8_t*>(schema.data()), schema.size()});
  const auto a = w.addChannel(s, "/a", "json", {{"k", "v"}});
  const auto b = w.addChannel(s, "/b", "json");
  w.addMetadata("fusedet.config", {{"config.yaml", "version: 1\n"}});
  for (int i = 0; i < 200; ++i) {
    w.write(a, 1000 + static_cast<std::uint64_t>(i) * 10, 0, payload(0, i));
    // channel b runs 5 ns "late" in the file: log times are not in file order
    if (i % 2 == 1) w.write(b, 1000 + static_cast<std::uint64_t>(i - 1) * 10 + 5 - 10, 0, payload(1, i / 2));
  }
  w.close();
  return p;
}

}  // namespace

TEST(McapCrc, KnownVectors) {
  const std::string s = "123456789";
  EXPECT_EQ(crc32({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()}), 0xCBF43926u);  // the CRC-32 check value
  EXPECT_EQ(crc32({}), 0u);
  // incremental = one shot
  const auto* p = reinterpret_cast<const std::uint8_t*>(s.data());
  EXPECT_EQ(crc32({p + 4, 5}, crc32({p, 4})), 0xCBF43926u);
}

namespace {
// Bit at a time, straight from the polynomial: shares nothing with the table-driven crc32.
std::uint32_t crcBitwise(const std::vector<std::uint8_t>& bytes) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::uint8_t b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}
}  // namespace

TEST(McapCrc, EightBytesAtATimeEqualsBitwiseAtEveryLengthAndSplit) {
  const std::string fox = "The quick brown fox jumps over the lazy dog";
  EXPECT_EQ(crc32({reinterpret_cast<const std::uint8_t*>(fox.data()), fox.size()}), 0x414FA339u);
  std::mt19937 rng(13);
  std::vector<std::uint8_t> all(4096 + 7);
  for (auto& b : all) b = static_cast<std::uint8_t>(rng());
  for (std::size_t offset = 0; offset < 8; ++offset)  // every alignment of the start
    for (std::size_t n : {0, 1, 7, 8, 9, 15, 16, 17, 63, 64, 65, 1000, 4096}) {
      const std::vector<std::uint8_t> v(all.begin() + static_cast<std::ptrdiff_t>(offset),
                                        all.begin() + static_cast<std::ptrdiff_t>(offset + n));
      EXPECT_EQ(crc32(v), crcBitwise(v)) << "offset " << offset << " length " << n;
      const std::size_t cut = n / 3;
      EXPECT_EQ(crc32({v.data() + cut, n - cut}, crc32({v.data(), cut})), crcBitwise(v)) << "split at " << cut;
    }
}

TEST(Mcap, RoundTripInTimeOrder) {
  const fs::path p = writeSample("roundtrip.mcap");
  McapReader r(p);
  const LogIndex& x = r.index();
  EXPECT_TRUE(x.intact()) << (x.problems.empty() ? "" : x.problems[0]);
  EXPECT_EQ(x.profile, "fusedet");
  ASSERT_EQ(x.channels.size(), 2u);
  EXPECT_EQ(x.channels.at(0).topic, "/a");
  EXPECT_EQ(x.channels.at(0).metadata.at("k"), "v");
  EXPECT_EQ(x.schemas.at(1).name, "test.A");
  EXPECT_EQ(x.messageCounts.at(0), 200u);
  EXPECT_EQ(x.messageCounts.at(1), 100u);
  EXPECT_GT(x.chunks.size(), 3u);  // 2000-byte chunks
  ASSERT_NE(x.findMetadata("fusedet.config"), nullptr);
  EXPECT_EQ(x.findMetadata("fusedet.config")->entries.at("config.yaml"), "version: 1\n");
  EXPECT_EQ(x.start, 995u);
  EXPECT_EQ(x.end, 2990u);

  auto cursor = r.messages();
  std::uint64_t last = 0;
  int n = 0, seenA = 0;
  while (auto m = cursor.next()) {
    EXPECT_GE(m->logTime, last) << "message " << n;
    last = m->logTime;
    if (m->channelId == 0) {
      EXPECT_EQ(m->data, payload(0, seenA));
      EXPECT_EQ(m->sequence, static_cast<std::uint32_t>(seenA));
      ++seenA;
    }
    ++n;
  }
  EXPECT_EQ(n, 300);
}

TEST(Mcap, SummaryAndFooterLayout) {
  const fs::path p = writeSample("layout.mcap");
  const auto b = readBytes(p);
  ASSERT_GT(b.size(), 16u + 29u);
  EXPECT_EQ(std::memcmp(b.data(), kMagic, 8), 0);
  EXPECT_EQ(std::memcmp(b.data() + b.size() - 8, kMagic, 8), 0);
  const std::size_t footer = b.size() - 8 - 29;  // opcode + length + 20 bytes
  EXPECT_EQ(b[footer], 0x02);
  EXPECT_EQ(le64(b, footer + 1), 20u);
  const std::uint64_t summaryStart = le64(b, footer + 9);
  const std::uint64_t offsetsStart = le64(b, footer + 17);
  ASSERT_LT(summaryStart, offsetsStart);
  ASSERT_LT(offsetsStart, footer);
  // the record before the summary is DataEnd
  EXPECT_EQ(b[summaryStart - 13], 0x0F);
  // summary CRC covers summary start .. the footer's summary_offset_start field
  std::uint32_t crc = 0;
  std::memcpy(&crc, b.data() + footer + 25, 4);
  EXPECT_EQ(crc32({b.data() + summaryStart, footer + 25 - summaryStart}), crc);
  // every summary offset points at a group of records of its opcode
  std::set<int> groups;
  for (std::size_t at = offsetsStart; at < footer;) {
    ASSERT_EQ(b[at], 0x0E);
    const std::uint8_t op = b[at + 9];
    const std::uint64_t start = le64(b, at + 10), length = le64(b, at + 18);
    EXPECT_EQ(b[start], op);
    EXPECT_LE(start + length, offsetsStart);
    groups.insert(op);
    at += 9 + le64(b, at + 1);
  }
  EXPECT_EQ(groups, (std::set<int>{0x03, 0x04, 0x08, 0x0B, 0x0D}));
}

TEST(Mcap, ChunkIndexesPointAtChunksAndMessageIndexes) {
  const fs::path p = writeSample("indexes.mcap");
  const auto b = readBytes(p);
  McapReader r(p);
  std::size_t chunkIndexes = 0;
  // walk the summary: each ChunkIndex's offset must hold a Chunk, its message index offsets MessageIndex records
  const std::size_t footer = b.size() - 8 - 29;
  for (std::size_t at = le64(b, footer + 9); at < footer; at += 9 + le64(b, at + 1)) {
    if (b[at] != 0x08) continue;
    const std::uint64_t chunkAt = le64(b, at + 9 + 16);
    EXPECT_EQ(b[chunkAt], 0x06);
    EXPECT_EQ(le64(b, at + 9 + 24), r.index().chunks[chunkIndexes].length);
    const std::size_t mapAt = at + 9 + 32;
    std::uint32_t mapLen = 0;
    std::memcpy(&mapLen, b.data() + mapAt, 4);
    for (std::size_t e = mapAt + 4; e < mapAt + 4 + mapLen; e += 10) EXPECT_EQ(b[le64(b, e + 2)], 0x07);
    ++chunkIndexes;
  }
  EXPECT_EQ(chunkIndexes, r.index().chunks.size());
}

TEST(Mcap, UncompressedChunksReadToo) {
  WriterOptions o;
  o.compress = false;
  McapReader r(writeSample("plain.mcap", o));
  EXPECT_TRUE(r.index().intact());
  EXPECT_EQ(r.index().messages, 300u);
}

TEST(Mcap, ChunkClosesOnLogTimeSpan) {
  const fs::path p = tempFile("span.mcap");
  WriterOptions o;
  o.chunkMaxNs = 1'000'000'000;
  {
    McapWriter w(p, o);
    const auto c = w.addChannel(0, "/x", "json");
    for (int i = 0; i < 50; ++i) w.write(c, static_cast<std::uint64_t>(i) * 100'000'000, 0, payload(0, i));  // 5 s
  }
  McapReader r(p);
  EXPECT_EQ(r.index().chunks.size(), 5u);  // 1 s per chunk
  EXPECT_TRUE(r.index().intact());
}

// Issue 37: fdatasync's result was not checked, so a chunk that never reached the disk counted as
// safe. /dev/null takes every write but has no fsync (the kernel answers EINVAL): the writer must
// say so at the first chunk it closes.
TEST(Mcap, AFailedFdatasyncIsAWriteError) {
  WriterOptions o;
  o.fsyncChunks = true;
  McapWriter w("/dev/null", o);
  const auto c = w.addChannel(0, "/x", "json");
  w.write(c, 1, 0, payload(0, 0));
  try {
    w.flush();
    FAIL() << "a chunk whose fdatasync failed was reported written";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/null: fdatasync: Invalid argument"), std::string::npos) << e.what();
  }
  o.fsyncChunks = false;  // the same writes without fdatasync succeed: it was fdatasync that failed
  McapWriter plain("/dev/null", o);
  plain.write(plain.addChannel(0, "/x", "json"), 1, 0, payload(0, 0));
  EXPECT_NO_THROW(plain.flush());
}

TEST(Mcap, NotMcapIsAnError) {
  const fs::path p = tempFile("text.mcap");
  writeBytes(p, std::vector<std::uint8_t>{'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd'});
  EXPECT_THROW(McapReader{p}, McapError);
  EXPECT_THROW(McapReader{tempFile("missing.mcap")}, McapError);
}

TEST(Mcap, DamagedChunkIsSkippedOthersStay) {
  const fs::path p = writeSample("damaged.mcap");
  McapReader good(p);
  const ChunkInfo c = good.index().chunks[1];
  auto b = readBytes(p);
  b[c.offset + c.length - 3] ^= 0x40;  // inside the compressed data
  const fs::path q = tempFile("damaged2.mcap");
  writeBytes(q, b);
  McapReader r(q);
  EXPECT_FALSE(r.index().intact());
  EXPECT_FALSE(r.index().chunks[1].ok);
  EXPECT_EQ(r.index().goodChunks(), good.index().chunks.size() - 1);
  EXPECT_EQ(r.index().messages, good.index().messages - c.messages);
  ASSERT_FALSE(r.index().problems.empty());
  int n = 0;
  auto cursor = r.messages();
  while (cursor.next()) ++n;
  EXPECT_EQ(static_cast<std::uint64_t>(n), r.index().messages);
}

// Cut at every offset: never a crash, the messages are exactly those of the complete chunks
// before the cut, and the truncation names the cut.
TEST(Mcap, TruncatedAtEveryOffset) {
  const fs::path p = writeSample("cut.mcap");
  const auto b = readBytes(p);
  McapReader whole(p);
  const auto& chunks = whole.index().chunks;
  const fs::path q = tempFile("cut2.mcap");
  for (std::size_t cut = 8; cut < b.size(); cut += 11) {
    writeBytes(q, std::span(b).first(cut));
    McapReader r(q);
    std::uint64_t expected = 0;
    std::uint64_t lastEnd = 0;
    for (const ChunkInfo& c : chunks)
      if (c.offset + c.length <= cut) expected += c.messages, lastEnd = c.offset + c.length;
    ASSERT_EQ(r.index().messages, expected) << "cut at " << cut;
    ASSERT_TRUE(r.index().truncation.has_value()) << "cut at " << cut;
    EXPECT_EQ(r.index().truncation->at, cut);
    EXPECT_EQ(r.index().truncation->lastChunkEnd, lastEnd) << "cut at " << cut;
    EXPECT_NE(r.index().truncation->describe().find("cut at byte " + std::to_string(cut)), std::string::npos);
    std::uint64_t n = 0;
    auto cursor = r.messages();
    while (cursor.next()) ++n;
    EXPECT_EQ(n, expected);
  }
}

// Random byte damage and random garbage: the reader reports, never crashes or hangs.
TEST(McapFuzz, MutatedFilesAndGarbage) {
  const fs::path p = writeSample("fuzz.mcap");
  const auto b = readBytes(p);
  std::mt19937 rng(12345);
  const fs::path q = tempFile("fuzz2.mcap");
  for (int round = 0; round < 300; ++round) {
    auto m = b;
    const int flips = 1 + static_cast<int>(rng() % 8);
    for (int k = 0; k < flips; ++k) m[8 + rng() % (m.size() - 8)] = static_cast<std::uint8_t>(rng());
    if (round % 3 == 0) m.resize(8 + rng() % (m.size() - 8));
    writeBytes(q, m);
    McapReader r(q);
    auto cursor = r.messages();
    std::uint64_t n = 0;
    while (cursor.next()) ++n;
    EXPECT_EQ(n, r.index().messages);
    EXPECT_LE(n, 300u);
  }
  for (int round = 0; round < 100; ++round) {
    std::vector<std::uint8_t> g(kMagic, kMagic + 8);
    const std::size_t len = rng() % 4000;
    for (std::size_t i = 0; i < len; ++i) g.push_back(static_cast<std::uint8_t>(rng()));
    // sometimes a plausible opcode with a huge length
    if (round % 4 == 0 && g.size() > 20) g[8] = 0x06, g[16] = 0x7F;
    writeBytes(q, g);
    McapReader r(q);
    EXPECT_FALSE(r.index().intact());
  }
}
