// SPDX-License-Identifier: Apache-2.0
#pragma once
// MCAP container records (https://mcap.dev/spec, format version 0), as plain data. Written by
// McapWriter, read by McapReader. All integers little-endian; times are uint64 nanoseconds
// (fusedet writes CLOCK_MONOTONIC stamps).

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace fusedet::drivers::mcap {

// "\x89MCAP0\r\n": begins and ends every file.
inline constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

enum class Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};
const char* opcodeName(std::uint8_t opcode);  // "Chunk", ... or "unknown"

// opcode (1) + length (8) in front of every record's content.
inline constexpr std::size_t kRecordPrefix = 9;

using StringMap = std::map<std::string, std::string>;

struct Schema {
  std::uint16_t id = 0;  // 0 is reserved (channel without schema)
  std::string name;
  std::string encoding;  // "jsonschema"
  std::vector<std::uint8_t> data;
};

struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schemaId = 0;
  std::string topic;
  std::string messageEncoding;  // "json"
  StringMap metadata;
};

struct Message {
  std::uint16_t channelId = 0;
  std::uint32_t sequence = 0;
  std::uint64_t logTime = 0;
  std::uint64_t publishTime = 0;
  std::vector<std::uint8_t> data;
};

struct Metadata {
  std::string name;
  StringMap entries;
};

// IEEE 802.3 CRC-32 (the zlib/PNG one) that MCAP uses for chunks, the data section and the summary.
std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t previous = 0);

}  // namespace fusedet::drivers::mcap
