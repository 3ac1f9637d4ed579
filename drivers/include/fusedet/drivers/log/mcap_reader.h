// SPDX-License-Identifier: Apache-2.0
#pragma once
// McapReader: reads an MCAP file (mcap_records.h) by one linear pass over its data section, so it
// needs neither the summary nor the footer: a file cut by a crash or power loss is read up to its
// last complete record, and each chunk is checked (CRC, decompression, record structure) on its
// own - a damaged chunk is reported and skipped, the chunks after it still count.
// When the summary is present it is checked against what the pass found.
//
// Messages come back in log-time order (ties: file order) through MessageCursor, which merges
// the chunks by their time ranges and keeps only overlapping chunks decompressed.

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <queue>
#include <string>
#include <vector>

#include "fusedet/drivers/log/mcap_records.h"
#include "fusedet/drivers/log/mcap_writer.h"  // McapError

namespace fusedet::drivers::mcap {

struct ChunkInfo {
  std::uint64_t offset = 0;       // file offset of the Chunk record
  std::uint64_t length = 0;       // whole record (opcode, length, content)
  std::uint64_t start = 0, end = 0;  // log-time span of its messages (as found, not as claimed)
  std::uint64_t messages = 0;
  std::uint64_t compressedSize = 0, uncompressedSize = 0;
  std::string compression;
  bool ok = false;
  std::string problem;  // when !ok: CRC mismatch, undecodable, bad record
};

// Where and how the data stopped early (a cut file).
struct Truncation {
  std::uint64_t at = 0;            // file size: where the bytes end
  std::uint64_t recordOffset = 0;  // the record the cut fell into
  std::string recordName;          // its opcode name ("Chunk", ...) or "record header"
  std::uint64_t recordNeeds = 0;   // bytes that record needed from its start
  std::uint64_t lastChunkEnd = 0;  // end of the last complete, intact chunk (0 = none)
  std::string describe() const;
};

struct LogIndex {
  std::uint64_t fileSize = 0;
  std::string profile, library;
  std::map<std::uint16_t, Schema> schemas;
  std::map<std::uint16_t, Channel> channels;
  std::vector<Metadata> metadata;
  std::vector<ChunkInfo> chunks;
  std::map<std::uint16_t, std::uint64_t> messageCounts;  // messages in intact chunks, per channel
  std::uint64_t messages = 0;
  std::uint64_t start = 0, end = 0;  // log-time span of those messages
  bool dataEnd = false;              // DataEnd record seen
  bool footer = false;               // footer and closing magic present
  std::optional<Truncation> truncation;
  std::vector<std::string> problems;  // everything else that is wrong, one line each
  std::vector<Message> looseMessages;  // Message records outside chunks (fusedet writes none)

  bool intact() const { return footer && !truncation && problems.empty(); }
  std::size_t goodChunks() const;
  const Channel* channel(const std::string& topic) const;
  const Metadata* findMetadata(const std::string& name) const;
};

class MessageCursor;

class McapReader {
 public:
  // Throws McapError when the file cannot be opened or does not start with the MCAP magic.
  // Everything after the magic is read leniently into index().
  explicit McapReader(const std::filesystem::path& path);
  ~McapReader();
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  const LogIndex& index() const { return index_; }
  const std::filesystem::path& path() const { return path_; }
  // The messages of one intact chunk, in file order (McapError if the file changed under us).
  std::vector<Message> chunkMessages(std::size_t chunk) const;
  // All messages of intact chunks in log-time order.
  MessageCursor messages() const;

 private:
  void scan();
  void readAt(std::uint64_t offset, std::uint8_t* out, std::size_t n) const;
  std::vector<std::uint8_t> decompress(const ChunkInfo& c, std::vector<std::uint8_t>& record, std::string& problem) const;
  std::filesystem::path path_;
  int fd_ = -1;
  LogIndex index_;
};

class MessageCursor {
 public:
  std::optional<Message> next();

 private:
  friend class McapReader;
  explicit MessageCursor(const McapReader& reader);
  void load(std::size_t seq);
  struct Item {
    std::uint64_t time;
    std::size_t seq, index;
    bool operator>(const Item& o) const { return time != o.time ? time > o.time : seq != o.seq ? seq > o.seq : index > o.index; }
  };
  const McapReader* reader_;
  std::vector<std::size_t> order_;  // intact chunks by start time (file order on ties)
  std::size_t nextChunk_ = 0;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> heap_;
  std::map<std::size_t, std::pair<std::vector<Message>, std::size_t>> loaded_;  // seq -> messages, left
};

}  // namespace fusedet::drivers::mcap
