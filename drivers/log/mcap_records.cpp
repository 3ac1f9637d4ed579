// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/log/mcap_records.h"

#include <array>

#include "mcap_codec.h"

namespace fusedet::drivers::mcap {

const char* opcodeName(std::uint8_t opcode) {
  static constexpr const char* kNames[] = {"invalid", "Header", "Footer", "Schema", "Channel", "Message",
                                           "Chunk", "MessageIndex", "ChunkIndex", "Attachment", "AttachmentIndex",
                                           "Statistics", "Metadata", "MetadataIndex", "SummaryOffset", "DataEnd"};
  return opcode < std::size(kNames) ? kNames[opcode] : "unknown";
}

namespace {
// Slicing-by-8 tables: t[0] is the classic byte table, t[k][b] = the CRC of byte b followed by k
// zero bytes. Eight bytes per step instead of one: a camera frame's chunk (~1.3 MB) is checked
// on every replay, and the byte-at-a-time loop cost ~7 ms of it.
using CrcTables = std::array<std::array<std::uint32_t, 256>, 8>;
CrcTables makeCrcTables() {
  CrcTables t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[0][i] = c;
  }
  for (std::size_t k = 1; k < 8; ++k)
    for (std::size_t i = 0; i < 256; ++i) t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFF];
  return t;
}
}  // namespace

std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t previous) {
  static const CrcTables t = makeCrcTables();
  std::uint32_t c = ~previous;
  const std::uint8_t* p = bytes.data();
  std::size_t n = bytes.size();
  for (; n >= 8; n -= 8, p += 8) {
    // Little-endian assembly of the next four bytes, independent of the host's byte order.
    const std::uint32_t lo = c ^ (std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
                                  std::uint32_t{p[3]} << 24);
    c = t[7][lo & 0xFF] ^ t[6][(lo >> 8) & 0xFF] ^ t[5][(lo >> 16) & 0xFF] ^ t[4][lo >> 24] ^ t[3][p[4]] ^
        t[2][p[5]] ^ t[1][p[6]] ^ t[0][p[7]];
  }
  for (; n > 0; --n, ++p) c = t[0][(c ^ *p) & 0xFF] ^ (c >> 8);
  return ~c;
}

void writeSchema(ByteWriter& w, const Schema& s) {
  const std::size_t at = w.beginRecord(Opcode::kSchema);
  w.u16(s.id);
  w.string(s.name);
  w.string(s.encoding);
  w.u32(static_cast<std::uint32_t>(s.data.size()));
  w.bytes(s.data);
  w.endRecord(at);
}

void writeChannel(ByteWriter& w, const Channel& c) {
  const std::size_t at = w.beginRecord(Opcode::kChannel);
  w.u16(c.id);
  w.u16(c.schemaId);
  w.string(c.topic);
  w.string(c.messageEncoding);
  w.map(c.metadata);
  w.endRecord(at);
}

void writeMessage(ByteWriter& w, const Message& m) {
  const std::size_t at = w.beginRecord(Opcode::kMessage);
  w.u16(m.channelId);
  w.u32(m.sequence);
  w.u64(m.logTime);
  w.u64(m.publishTime);
  w.bytes(m.data);
  w.endRecord(at);
}

void writeMetadata(ByteWriter& w, const Metadata& m) {
  const std::size_t at = w.beginRecord(Opcode::kMetadata);
  w.string(m.name);
  w.map(m.entries);
  w.endRecord(at);
}

Schema readSchema(ByteReader r) {
  Schema s;
  s.id = r.u16();
  s.name = r.string();
  s.encoding = r.string();
  auto d = r.take(r.u32());
  s.data.assign(d.begin(), d.end());
  return s;
}

Channel readChannel(ByteReader r) {
  Channel c;
  c.id = r.u16();
  c.schemaId = r.u16();
  c.topic = r.string();
  c.messageEncoding = r.string();
  c.metadata = r.map();
  return c;
}

Message readMessage(ByteReader r) {
  Message m;
  m.channelId = r.u16();
  m.sequence = r.u32();
  m.logTime = r.u64();
  m.publishTime = r.u64();
  auto d = r.rest();
  m.data.assign(d.begin(), d.end());
  return m;
}

Metadata readMetadata(ByteReader r) {
  Metadata m;
  m.name = r.string();
  m.entries = r.map();
  return m;
}

}  // namespace fusedet::drivers::mcap
