// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/log/mcap_writer.h"

#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "mcap_codec.h"

namespace fusedet::drivers::mcap {

McapWriter::McapWriter(const std::filesystem::path& path, WriterOptions options)
    : path_(path), options_(std::move(options)) {
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) fail(std::string("cannot create: ") + std::strerror(errno));
  std::vector<std::uint8_t> head(std::begin(kMagic), std::end(kMagic));
  ByteWriter w(head);
  const std::size_t at = w.beginRecord(Opcode::kHeader);
  w.string(options_.profile);
  w.string(options_.library);
  w.endRecord(at);
  append(head);
}

McapWriter::~McapWriter() {
  try {
    close();
  } catch (const std::exception&) {  // NOLINT(bugprone-empty-catch): a destructor must not throw
  }
  if (file_) std::fclose(file_);
}

void McapWriter::fail(const std::string& what) const { throw McapError(path_.string() + ": " + what); }

void McapWriter::append(std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) return;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
    fail(std::string("write error: ") + std::strerror(errno));
  dataCrc_ = crc32(bytes, dataCrc_);
  offset_ += bytes.size();
}

std::uint16_t McapWriter::addSchema(const std::string& name, const std::string& encoding,
                                    std::span<const std::uint8_t> data) {
  if (closed_) fail("addSchema after close");
  Schema s{static_cast<std::uint16_t>(schemas_.size() + 1), name, encoding, {data.begin(), data.end()}};
  std::vector<std::uint8_t> rec;
  ByteWriter w(rec);
  writeSchema(w, s);
  append(rec);  // before any chunk that uses it: a sequential reader sees it first
  schemas_.push_back(std::move(s));
  return schemas_.back().id;
}

std::uint16_t McapWriter::addChannel(std::uint16_t schemaId, const std::string& topic, const std::string& messageEncoding,
                                     const StringMap& metadata) {
  if (closed_) fail("addChannel after close");
  if (schemaId > schemas_.size()) fail("addChannel " + topic + ": unknown schema id " + std::to_string(schemaId));
  Channel c{static_cast<std::uint16_t>(channels_.size()), schemaId, topic, messageEncoding, metadata};
  std::vector<std::uint8_t> rec;
  ByteWriter w(rec);
  writeChannel(w, c);
  append(rec);
  channels_.push_back(std::move(c));
  return channels_.back().id;
}

void McapWriter::write(std::uint16_t channelId, std::uint64_t logTime, std::uint64_t publishTime,
                       std::span<const std::uint8_t> data) {
  if (closed_) fail("write after close");
  if (channelId >= channels_.size()) fail("write: unknown channel id " + std::to_string(channelId));
  if (!chunk_.empty() && (std::max(chunkEnd_, logTime) - std::min(chunkStart_, logTime) > options_.chunkMaxNs))
    closeChunk();
  if (chunk_.empty()) chunkStart_ = chunkEnd_ = logTime;
  chunkStart_ = std::min(chunkStart_, logTime);
  chunkEnd_ = std::max(chunkEnd_, logTime);
  chunkMessages_[channelId].emplace_back(logTime, chunk_.size());
  ByteWriter w(chunk_);
  const std::size_t at = w.beginRecord(Opcode::kMessage);
  w.u16(channelId);
  w.u32(sequences_[channelId]++);
  w.u64(logTime);
  w.u64(publishTime);
  w.bytes(data);
  w.endRecord(at);
  ++channelCounts_[channelId];
  messageStart_ = messageCount_ == 0 ? logTime : std::min(messageStart_, logTime);
  messageEnd_ = messageCount_ == 0 ? logTime : std::max(messageEnd_, logTime);
  ++messageCount_;
  if (chunk_.size() >= options_.chunkBytes) closeChunk();
}

void McapWriter::addMetadata(const std::string& name, const StringMap& entries) {
  if (closed_) fail("addMetadata after close");
  std::vector<std::uint8_t> rec;
  ByteWriter w(rec);
  writeMetadata(w, Metadata{name, entries});
  metadataIndex_.emplace_back(offset_, rec.size());
  metadataNames_.push_back(name);
  append(rec);
}

void McapWriter::closeChunk() {
  if (chunk_.empty()) return;
  std::vector<std::uint8_t> compressed;
  std::string compression;
  if (options_.compress) {
    compressed.resize(ZSTD_compressBound(chunk_.size()));
    const std::size_t n = ZSTD_compress(compressed.data(), compressed.size(), chunk_.data(), chunk_.size(), options_.zstdLevel);
    if (ZSTD_isError(n)) fail(std::string("zstd: ") + ZSTD_getErrorName(n));
    compressed.resize(n);
    compression = "zstd";
  } else {
    compressed = chunk_;
  }
  ChunkIndexEntry entry;
  entry.start = chunkStart_;
  entry.end = chunkEnd_;
  entry.offset = offset_;
  entry.compressedSize = compressed.size();
  entry.uncompressedSize = chunk_.size();

  std::vector<std::uint8_t> rec;
  rec.reserve(compressed.size() + 64);
  ByteWriter w(rec);
  const std::size_t at = w.beginRecord(Opcode::kChunk);
  w.u64(chunkStart_);
  w.u64(chunkEnd_);
  w.u64(chunk_.size());
  w.u32(crc32(chunk_));
  w.string(compression);
  w.u64(compressed.size());
  w.bytes(compressed);
  w.endRecord(at);
  entry.length = rec.size();
  // Message indexes follow their chunk: per channel, (log time, offset in the uncompressed records).
  std::uint64_t indexAt = offset_ + rec.size();
  for (auto& [channel, list] : chunkMessages_) {
    std::stable_sort(list.begin(), list.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    const std::size_t before = rec.size();
    const std::size_t r = w.beginRecord(Opcode::kMessageIndex);
    w.u16(channel);
    const std::size_t arr = w.begin32();
    for (const auto& [t, off] : list) w.u64(t), w.u64(off);
    w.end32(arr);
    w.endRecord(r);
    entry.indexOffsets[channel] = indexAt;
    indexAt += rec.size() - before;
  }
  entry.indexLength = rec.size() - entry.length;
  append(rec);
  chunkIndex_.push_back(std::move(entry));
  chunk_.clear();
  chunkMessages_.clear();
  if (std::fflush(file_) != 0) fail(std::string("write error: ") + std::strerror(errno));
  // The chunk is only safe from a power cut once this succeeded: an error (EIO, ENOSPC on some
  // file systems) is a write error like any other.
  if (options_.fsyncChunks && ::fdatasync(fileno(file_)) != 0) fail(std::string("fdatasync: ") + std::strerror(errno));
}

void McapWriter::flush() {
  if (closed_) return;
  closeChunk();
  if (std::fflush(file_) != 0) fail(std::string("write error: ") + std::strerror(errno));
}

void McapWriter::close() {
  if (closed_ || !file_) return;
  closeChunk();
  closed_ = true;
  std::vector<std::uint8_t> out;
  ByteWriter w(out);
  std::size_t at = w.beginRecord(Opcode::kDataEnd);
  w.u32(dataCrc_);
  w.endRecord(at);
  append(out);
  out.clear();

  // Summary: groups of one opcode each, located by summary offsets.
  const std::uint64_t summaryStart = offset_;
  std::vector<std::tuple<Opcode, std::uint64_t, std::uint64_t>> groups;
  auto group = [&](Opcode op, auto&& body) {
    const std::size_t before = out.size();
    body();
    if (out.size() > before) groups.emplace_back(op, summaryStart + before, out.size() - before);
  };
  group(Opcode::kSchema, [&] {
    for (const Schema& s : schemas_) writeSchema(w, s);
  });
  group(Opcode::kChannel, [&] {
    for (const Channel& c : channels_) writeChannel(w, c);
  });
  group(Opcode::kStatistics, [&] {
    at = w.beginRecord(Opcode::kStatistics);
    w.u64(messageCount_);
    w.u16(static_cast<std::uint16_t>(schemas_.size()));
    w.u32(static_cast<std::uint32_t>(channels_.size()));
    w.u32(0);  // attachments
    w.u32(static_cast<std::uint32_t>(metadataIndex_.size()));
    w.u32(static_cast<std::uint32_t>(chunkIndex_.size()));
    w.u64(messageStart_);
    w.u64(messageEnd_);
    const std::size_t m = w.begin32();
    for (const auto& [ch, n] : channelCounts_) w.u16(ch), w.u64(n);
    w.end32(m);
    w.endRecord(at);
  });
  group(Opcode::kChunkIndex, [&] {
    for (const ChunkIndexEntry& c : chunkIndex_) {
      at = w.beginRecord(Opcode::kChunkIndex);
      w.u64(c.start);
      w.u64(c.end);
      w.u64(c.offset);
      w.u64(c.length);
      const std::size_t m = w.begin32();
      for (const auto& [ch, off] : c.indexOffsets) w.u16(ch), w.u64(off);
      w.end32(m);
      w.u64(c.indexLength);
      w.string(options_.compress ? "zstd" : "");
      w.u64(c.compressedSize);
      w.u64(c.uncompressedSize);
      w.endRecord(at);
    }
  });
  group(Opcode::kMetadataIndex, [&] {
    for (std::size_t i = 0; i < metadataIndex_.size(); ++i) {
      at = w.beginRecord(Opcode::kMetadataIndex);
      w.u64(metadataIndex_[i].first);
      w.u64(metadataIndex_[i].second);
      w.string(metadataNames_[i]);
      w.endRecord(at);
    }
  });
  const std::uint64_t summaryOffsetStart = summaryStart + out.size();
  for (const auto& [op, start, length] : groups) {
    at = w.beginRecord(Opcode::kSummaryOffset);
    w.u8(static_cast<std::uint8_t>(op));
    w.u64(start);
    w.u64(length);
    w.endRecord(at);
  }
  // Footer; its CRC covers the summary and the footer's fields before it.
  w.u8(static_cast<std::uint8_t>(Opcode::kFooter));
  w.u64(8 + 8 + 4);  // the length is part of what the CRC covers, so it is written directly
  w.u64(summaryStart);
  w.u64(summaryOffsetStart);
  w.u32(crc32(out));
  w.bytes(kMagic);
  if (std::fwrite(out.data(), 1, out.size(), file_) != out.size()) fail(std::string("write error: ") + std::strerror(errno));
  offset_ += out.size();
  const bool ok = std::fflush(file_) == 0;
  const int closeResult = std::fclose(file_);
  file_ = nullptr;
  if (!ok || closeResult != 0) fail(std::string("write error at close: ") + std::strerror(errno));
}

}  // namespace fusedet::drivers::mcap
