// SPDX-License-Identifier: Apache-2.0
#pragma once
// McapWriter: writes one MCAP file (mcap_records.h) - chunked, zstd-compressed, each chunk with
// its CRC and message indexes, and at close() the summary (schemas, channels, statistics, chunk
// and metadata indexes, summary offsets) and footer.
//
// Crash safety: schemas, channels and metadata go to the file at once; messages collect in the
// open chunk, which is written (and flushed to the OS) when it reaches `chunkBytes`, when its
// first message is older than `chunkMaxNs` by log time, or on flush(). A crash therefore loses at
// most the open chunk; McapReader reads such a file up to its last complete chunk.
// Not thread-safe: logs::Recorder serialises writers from several driver threads.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "fusedet/drivers/log/mcap_records.h"

namespace fusedet::drivers::mcap {

// I/O failures (cannot create, disk full) name the file.
class McapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct WriterOptions {
  std::size_t chunkBytes = 4u << 20;         // uncompressed chunk size that closes a chunk
  std::uint64_t chunkMaxNs = 1'000'000'000;  // log-time span that closes a chunk (live: bounded loss)
  bool compress = true;                      // zstd; false = "" (uncompressed chunks)
  int zstdLevel = 3;
  bool fsyncChunks = false;                  // fdatasync after each chunk (power-cut safety, slower)
  std::string profile = "fusedet";
  std::string library = "fusedet";
};

class McapWriter {
 public:
  McapWriter(const std::filesystem::path& path, WriterOptions options = {});
  ~McapWriter();  // closes (errors are swallowed there: call close() to see them)
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  std::uint16_t addSchema(const std::string& name, const std::string& encoding, std::span<const std::uint8_t> data);
  std::uint16_t addChannel(std::uint16_t schemaId, const std::string& topic, const std::string& messageEncoding,
                           const StringMap& metadata = {});
  // Messages may come in any time order; sequence numbers count per channel from 0.
  void write(std::uint16_t channelId, std::uint64_t logTime, std::uint64_t publishTime, std::span<const std::uint8_t> data);
  void addMetadata(const std::string& name, const StringMap& entries);
  // Writes the open chunk (if any) and flushes the file to the OS.
  void flush();
  // Writes the open chunk, data end, summary and footer; closes the file. Idempotent.
  void close();

  const std::filesystem::path& path() const { return path_; }
  std::uint64_t messageCount() const { return messageCount_; }
  std::uint64_t bytesWritten() const { return offset_; }

 private:
  struct ChunkIndexEntry {
    std::uint64_t start = 0, end = 0, offset = 0, length = 0, indexLength = 0, compressedSize = 0, uncompressedSize = 0;
    std::map<std::uint16_t, std::uint64_t> indexOffsets;
  };
  void append(std::span<const std::uint8_t> bytes);  // to the file, CRC of the data section
  void closeChunk();
  void fail(const std::string& what) const;

  std::filesystem::path path_;
  WriterOptions options_;
  std::FILE* file_ = nullptr;
  std::uint64_t offset_ = 0;
  std::uint32_t dataCrc_ = 0;
  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  std::map<std::uint16_t, std::uint32_t> sequences_;
  std::map<std::uint16_t, std::uint64_t> channelCounts_;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> metadataIndex_;  // offset, length
  std::vector<std::string> metadataNames_;
  std::vector<ChunkIndexEntry> chunkIndex_;
  // The open chunk: records, per-channel (log time, offset) index, time span.
  std::vector<std::uint8_t> chunk_;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunkMessages_;
  std::uint64_t chunkStart_ = 0, chunkEnd_ = 0;
  std::uint64_t messageCount_ = 0, messageStart_ = 0, messageEnd_ = 0;
  bool closed_ = false;
};

}  // namespace fusedet::drivers::mcap
