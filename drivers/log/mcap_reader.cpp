// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/log/mcap_reader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <new>
#include <span>

#include "mcap_codec.h"

namespace fusedet::drivers::mcap {

namespace {
// Larger claimed chunk sizes are corruption, not data (the writer closes chunks at a few MiB).
constexpr std::uint64_t kMaxChunkBytes = 1ull << 30;

std::string byteAt(std::uint64_t offset) { return "byte " + std::to_string(offset); }

// zstd data -> exactly `size` bytes. The output grows with what really comes out (doubling from
// a few times the input), so a corrupt header that claims up to kMaxChunkBytes costs no more
// memory than the data actually decompresses to.
std::vector<std::uint8_t> inflate(std::span<const std::uint8_t> data, std::uint64_t size) {
  std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> ctx(ZSTD_createDCtx(), ZSTD_freeDCtx);
  if (!ctx) throw std::bad_alloc();
  std::vector<std::uint8_t> out(static_cast<std::size_t>(std::min<std::uint64_t>(size, std::max<std::uint64_t>(data.size() * 4, 1 << 16))));
  ZSTD_inBuffer in{data.data(), data.size(), 0};
  std::size_t produced = 0;
  std::size_t left = 1;  // ZSTD_decompressStream's hint: 0 = a frame is complete
  while (in.pos < in.size || left != 0) {
    if (produced == out.size() && out.size() >= size) {
      // Full at the claimed size: what is left may only end the frame (its checksum), no data.
      std::uint8_t extra = 0;
      ZSTD_outBuffer o{&extra, 1, 0};
      const std::size_t before = in.pos;
      left = ZSTD_decompressStream(ctx.get(), &o, &in);
      if (ZSTD_isError(left)) throw RecordError(std::string("zstd: ") + ZSTD_getErrorName(left));
      if (o.pos != 0)
        throw RecordError("zstd data decompresses to more than the " + std::to_string(size) + " bytes the header says");
      if (in.pos == before) throw RecordError("zstd: data ends inside a frame");
      continue;
    }
    if (produced == out.size()) out.resize(static_cast<std::size_t>(std::min<std::uint64_t>(size, std::uint64_t{out.size()} * 2)));
    ZSTD_outBuffer o{out.data(), out.size(), produced};
    const std::size_t before = in.pos;
    left = ZSTD_decompressStream(ctx.get(), &o, &in);
    if (ZSTD_isError(left)) throw RecordError(std::string("zstd: ") + ZSTD_getErrorName(left));
    const bool progress = o.pos != produced || in.pos != before;
    produced = o.pos;
    if (!progress && produced < out.size()) throw RecordError("zstd: data ends inside a frame");
  }
  if (produced != size)
    throw RecordError("decompressed to " + std::to_string(produced) + " bytes, header says " + std::to_string(size));
  out.resize(produced);
  return out;
}
}  // namespace

std::string Truncation::describe() const {
  std::string s = recordOffset == this->at
                      ? "cut at " + byteAt(this->at) + " between two records (no summary, no footer)"
                      : "cut at " + byteAt(this->at) + " inside a " + recordName + " record starting at " + byteAt(recordOffset) +
                            " (it needs " + std::to_string(recordNeeds) + " bytes, " +
                            std::to_string(this->at - recordOffset) + " present)";
  s += lastChunkEnd ? "; the last complete chunk ends at " + byteAt(lastChunkEnd) : "; no complete chunk before it";
  return s;
}

std::size_t LogIndex::goodChunks() const {
  return static_cast<std::size_t>(std::count_if(chunks.begin(), chunks.end(), [](const ChunkInfo& c) { return c.ok; }));
}

const Channel* LogIndex::channel(const std::string& topic) const {
  for (const auto& [id, c] : channels)
    if (c.topic == topic) return &c;
  return nullptr;
}

const Metadata* LogIndex::findMetadata(const std::string& name) const {
  for (const Metadata& m : metadata)
    if (m.name == name) return &m;
  return nullptr;
}

McapReader::McapReader(const std::filesystem::path& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw McapError(path.string() + ": cannot open: " + std::strerror(errno));
  struct stat st{};
  if (::fstat(fd_, &st) != 0) throw McapError(path.string() + ": " + std::strerror(errno));
  index_.fileSize = static_cast<std::uint64_t>(st.st_size);
  std::uint8_t magic[8] = {};
  if (index_.fileSize < 8 || (readAt(0, magic, 8), std::memcmp(magic, kMagic, 8) != 0)) {
    ::close(fd_);
    fd_ = -1;
    throw McapError(path.string() + ": not an MCAP file (no MCAP magic at the start)");
  }
  scan();
}

McapReader::~McapReader() {
  if (fd_ >= 0) ::close(fd_);
}

void McapReader::readAt(std::uint64_t offset, std::uint8_t* out, std::size_t n) const {
  std::size_t done = 0;
  while (done < n) {
    const ssize_t r = ::pread(fd_, out + done, n - done, static_cast<off_t>(offset + done));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) throw McapError(path_.string() + ": read error at " + byteAt(offset + done) + (r < 0 ? std::string(": ") + std::strerror(errno) : ": file shrank"));
    done += static_cast<std::size_t>(r);
  }
}

// Chunk record content -> its uncompressed records; empty result with `problem` set on damage.
std::vector<std::uint8_t> McapReader::decompress(const ChunkInfo& c, std::vector<std::uint8_t>& record,
                                                 std::string& problem) const {
  try {
    ByteReader r(record);
    r.u64(), r.u64();
    const std::uint64_t size = r.u64();
    const std::uint32_t crc = r.u32();
    const std::string compression = r.string();
    const auto data = r.take(r.u64());
    if (size > kMaxChunkBytes) throw RecordError("implausible uncompressed size " + std::to_string(size));
    std::vector<std::uint8_t> out;
    if (compression.empty()) {
      if (data.size() != size) throw RecordError("uncompressed chunk of " + std::to_string(data.size()) + " bytes claims " + std::to_string(size));
      out.assign(data.begin(), data.end());
    } else if (compression == "zstd") {
      out = inflate(data, size);
    } else {
      throw RecordError("unsupported compression '" + compression + "'");
    }
    if (crc != 0 && crc32(out) != crc) throw RecordError("CRC mismatch (uncompressed data damaged)");
    return out;
  } catch (const RecordError& e) {
    problem = "chunk at " + byteAt(c.offset) + ": " + e.what();
    return {};
  }
}

void McapReader::scan() {
  LogIndex& x = index_;
  std::uint64_t pos = 8;
  std::uint64_t lastChunkEnd = 0;
  std::uint64_t summaryStart = 0;
  std::uint32_t dataCrc = crc32(std::span<const std::uint8_t>(kMagic, 8));
  bool inSummary = false;
  std::vector<std::uint8_t> content;
  std::optional<std::uint64_t> statisticsMessages;
  auto addChannel = [&](Channel c) {
    auto [it, fresh] = x.channels.emplace(c.id, c);
    if (!fresh && (it->second.topic != c.topic || it->second.schemaId != c.schemaId))
      x.problems.push_back("channel " + std::to_string(c.id) + " redefined (" + it->second.topic + " -> " + c.topic + ")");
  };
  auto addSchema = [&](Schema s) {
    auto [it, fresh] = x.schemas.emplace(s.id, s);
    if (!fresh && it->second.name != s.name) x.problems.push_back("schema " + std::to_string(s.id) + " redefined");
  };
  auto countMessage = [&](const Message& m) {
    x.start = x.messages == 0 ? m.logTime : std::min(x.start, m.logTime);
    x.end = x.messages == 0 ? m.logTime : std::max(x.end, m.logTime);
    ++x.messages;
    ++x.messageCounts[m.channelId];
  };

  while (pos < x.fileSize) {
    std::uint8_t prefix[kRecordPrefix];
    if (x.fileSize - pos == 8) {  // the closing magic, legal only after the footer
      readAt(pos, prefix, 8);
      if (std::memcmp(prefix, kMagic, 8) == 0 && x.footer) break;
    }
    if (x.fileSize - pos < kRecordPrefix) {
      x.truncation = Truncation{x.fileSize, pos, "record header", kRecordPrefix, lastChunkEnd};
      break;
    }
    readAt(pos, prefix, kRecordPrefix);
    const std::uint8_t opcode = prefix[0];
    std::uint64_t len = 0;
    for (int i = 0; i < 8; ++i) len |= static_cast<std::uint64_t>(prefix[1 + i]) << (8 * i);
    if (len > x.fileSize - pos - kRecordPrefix) {
      const std::uint64_t needs = len > (1ull << 62) ? len : len + kRecordPrefix;
      x.truncation = Truncation{x.fileSize, pos, opcodeName(opcode), needs, lastChunkEnd};
      break;
    }
    if (x.footer) {
      x.problems.push_back("bytes after the footer at " + byteAt(pos));
      break;
    }
    const std::uint64_t recordEnd = pos + kRecordPrefix + len;
    const auto op = static_cast<Opcode>(opcode);
    if (op == Opcode::kDataEnd) inSummary = true;
    if (op != Opcode::kChunk && len > kMaxChunkBytes) {
      x.problems.push_back(std::string(opcodeName(opcode)) + " record at " + byteAt(pos) + " claims " + std::to_string(len) + " bytes; stopped reading");
      break;
    }
    content.resize(static_cast<std::size_t>(std::min(len, kMaxChunkBytes + 64)));
    if (len <= kMaxChunkBytes + 64) readAt(pos + kRecordPrefix, content.data(), content.size());
    if (!inSummary) {
      dataCrc = crc32(std::span<const std::uint8_t>(prefix, kRecordPrefix), dataCrc);
      dataCrc = crc32(content, dataCrc);
    }
    try {
      switch (op) {
        case Opcode::kHeader: {
          if (pos != 8) x.problems.push_back("Header record at " + byteAt(pos) + " (expected at byte 8)");
          ByteReader r(content);
          x.profile = r.string();
          x.library = r.string();
          break;
        }
        case Opcode::kSchema: addSchema(readSchema(ByteReader(content))); break;
        case Opcode::kChannel: addChannel(readChannel(ByteReader(content))); break;
        case Opcode::kMetadata:
          if (!inSummary) x.metadata.push_back(readMetadata(ByteReader(content)));
          break;
        case Opcode::kMessage: {
          Message m = readMessage(ByteReader(content));
          countMessage(m);
          x.looseMessages.push_back(std::move(m));
          break;
        }
        case Opcode::kChunk: {
          ChunkInfo c;
          c.offset = pos;
          c.length = kRecordPrefix + len;
          if (len > kMaxChunkBytes + 64) {
            c.problem = "chunk at " + byteAt(pos) + ": implausible length " + std::to_string(len);
          } else {
            ByteReader h(content);
            h.u64(), h.u64();
            c.uncompressedSize = h.u64();
            h.u32();
            c.compression = h.string();
            c.compressedSize = h.u64();
            std::vector<std::uint8_t> records = decompress(c, content, c.problem);
            if (c.problem.empty()) {
              // Parse all records first: a chunk counts whole or not at all.
              std::vector<Message> found;
              std::vector<Schema> schemas;
              std::vector<Channel> channels;
              try {
                ByteReader r(records);
                while (!r.done()) {
                  const std::uint8_t innerOp = r.u8();
                  ByteReader body(r.take(r.u64()));
                  if (innerOp == static_cast<std::uint8_t>(Opcode::kMessage)) found.push_back(readMessage(body));
                  else if (innerOp == static_cast<std::uint8_t>(Opcode::kSchema)) schemas.push_back(readSchema(body));
                  else if (innerOp == static_cast<std::uint8_t>(Opcode::kChannel)) channels.push_back(readChannel(body));
                }
              } catch (const RecordError& e) {
                c.problem = "chunk at " + byteAt(pos) + ": bad record inside: " + e.what();
              }
              if (c.problem.empty()) {
                for (Schema& s : schemas) addSchema(std::move(s));
                for (Channel& ch : channels) addChannel(std::move(ch));
                for (const Message& m : found) {
                  c.start = c.messages == 0 ? m.logTime : std::min(c.start, m.logTime);
                  c.end = c.messages == 0 ? m.logTime : std::max(c.end, m.logTime);
                  ++c.messages;
                  countMessage(m);
                }
                c.ok = true;
                lastChunkEnd = recordEnd;
              }
            }
          }
          if (!c.ok) x.problems.push_back(c.problem);
          x.chunks.push_back(std::move(c));
          break;
        }
        case Opcode::kDataEnd: {
          x.dataEnd = true;
          summaryStart = recordEnd;
          const std::uint32_t stored = ByteReader(content).u32();
          if (stored != 0 && stored != dataCrc) x.problems.push_back("data section CRC mismatch (DataEnd at " + byteAt(pos) + ")");
          break;
        }
        case Opcode::kStatistics:
          statisticsMessages = ByteReader(content).u64();
          break;
        case Opcode::kFooter: {
          ByteReader r(content);
          const std::uint64_t start = r.u64();
          r.u64();
          const std::uint32_t crc = r.u32();
          if (start != 0 && crc != 0) {
            if (start < pos) {
              std::vector<std::uint8_t> summary(static_cast<std::size_t>(pos + kRecordPrefix + 16 - start));
              readAt(start, summary.data(), summary.size());
              if (crc32(summary) != crc) x.problems.push_back("summary CRC mismatch (footer at " + byteAt(pos) + ")");
            } else {
              x.problems.push_back("footer points its summary at " + byteAt(start) + ", after itself");
            }
          }
          if (summaryStart != 0 && start != 0 && start != summaryStart)
            x.problems.push_back("footer says the summary starts at " + byteAt(start) + ", it starts at " + byteAt(summaryStart));
          x.footer = true;
          break;
        }
        default: break;  // indexes are rebuilt by this pass; unknown opcodes are skipped (spec)
      }
    } catch (const RecordError& e) {
      x.problems.push_back(std::string(opcodeName(opcode)) + " record at " + byteAt(pos) + ": " + e.what());
    }
    pos = recordEnd;
  }
  if (!x.footer && !x.truncation)  // cut exactly between two records
    x.truncation = Truncation{x.fileSize, x.fileSize, "", 0, lastChunkEnd};
  if (x.footer) {
    std::uint8_t tail[8] = {};
    if (x.fileSize < 8 || (readAt(x.fileSize - 8, tail, 8), std::memcmp(tail, kMagic, 8) != 0)) {
      x.footer = false;
      x.problems.push_back("closing magic missing");
    }
  }
  if (x.footer && !x.dataEnd) x.problems.push_back("no DataEnd record before the footer");
  if (statisticsMessages && !x.truncation && *statisticsMessages != x.messages)
    x.problems.push_back("summary counts " + std::to_string(*statisticsMessages) + " messages, the chunks hold " +
                         std::to_string(x.messages));
  for (const auto& [id, n] : x.messageCounts)
    if (!x.channels.count(id)) x.problems.push_back(std::to_string(n) + " messages on undefined channel " + std::to_string(id));
}

std::vector<Message> McapReader::chunkMessages(std::size_t chunk) const {
  const ChunkInfo& c = index_.chunks.at(chunk);
  if (!c.ok) throw McapError(path_.string() + ": " + c.problem);
  std::vector<std::uint8_t> content(static_cast<std::size_t>(c.length - kRecordPrefix));
  readAt(c.offset + kRecordPrefix, content.data(), content.size());
  std::string problem;
  const std::vector<std::uint8_t> records = decompress(c, content, problem);
  if (!problem.empty()) throw McapError(path_.string() + ": " + problem + " (file changed while open?)");
  std::vector<Message> out;
  out.reserve(static_cast<std::size_t>(c.messages));
  try {
    ByteReader r(records);
    while (!r.done()) {
      const std::uint8_t op = r.u8();
      ByteReader body(r.take(r.u64()));
      if (op == static_cast<std::uint8_t>(Opcode::kMessage)) out.push_back(readMessage(body));
    }
  } catch (const RecordError& e) {
    throw McapError(path_.string() + ": chunk at " + byteAt(c.offset) + ": " + e.what());
  }
  return out;
}

MessageCursor McapReader::messages() const { return MessageCursor(*this); }

MessageCursor::MessageCursor(const McapReader& reader) : reader_(&reader) {
  const auto& chunks = reader.index().chunks;
  for (std::size_t i = 0; i < chunks.size(); ++i)
    if (chunks[i].ok && chunks[i].messages > 0) order_.push_back(i);
  std::stable_sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) { return chunks[a].start < chunks[b].start; });
  const auto& loose = reader.index().looseMessages;
  if (!loose.empty()) {
    const std::size_t seq = order_.size();  // after every chunk on ties
    loaded_[seq] = {loose, loose.size()};
    for (std::size_t i = 0; i < loose.size(); ++i) heap_.push(Item{loose[i].logTime, seq, i});
  }
}

void MessageCursor::load(std::size_t seq) {
  std::vector<Message> m = reader_->chunkMessages(order_[seq]);
  if (m.empty()) return;
  for (std::size_t i = 0; i < m.size(); ++i) heap_.push(Item{m[i].logTime, seq, i});
  const std::size_t n = m.size();
  loaded_[seq] = {std::move(m), n};
}

std::optional<Message> MessageCursor::next() {
  const auto& chunks = reader_->index().chunks;
  while (nextChunk_ < order_.size() && (heap_.empty() || chunks[order_[nextChunk_]].start <= heap_.top().time))
    load(nextChunk_++);
  if (heap_.empty()) return std::nullopt;
  const Item top = heap_.top();
  heap_.pop();
  auto it = loaded_.find(top.seq);
  Message m = std::move(it->second.first[top.index]);
  if (--it->second.second == 0) loaded_.erase(it);
  return m;
}

}  // namespace fusedet::drivers::mcap
