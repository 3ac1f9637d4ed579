// SPDX-License-Identifier: Apache-2.0
#pragma once
// Little-endian field codec of MCAP records (internal to drivers/log): ByteWriter appends fields,
// ByteReader reads them with bounds checks and throws RecordError on any overrun, so a corrupt
// length field can never read past its record.

#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "fusedet/drivers/log/mcap_records.h"

namespace fusedet::drivers::mcap {

class RecordError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ByteWriter {
 public:
  explicit ByteWriter(std::vector<std::uint8_t>& out) : out_(out) {}
  void u8(std::uint8_t v) { out_.push_back(v); }
  void u16(std::uint16_t v) { le(v, 2); }
  void u32(std::uint32_t v) { le(v, 4); }
  void u64(std::uint64_t v) { le(v, 8); }
  void bytes(std::span<const std::uint8_t> b) { out_.insert(out_.end(), b.begin(), b.end()); }
  void string(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    out_.insert(out_.end(), s.begin(), s.end());
  }
  void map(const StringMap& m) {
    const std::size_t at = begin32();
    for (const auto& [k, v] : m) string(k), string(v);
    end32(at);
  }
  // A uint32 byte-length prefix filled in by end32 (maps and arrays).
  std::size_t begin32() {
    u32(0);
    return out_.size();
  }
  void end32(std::size_t at) {
    const auto n = static_cast<std::uint32_t>(out_.size() - at);
    for (int i = 0; i < 4; ++i) out_[at - 4 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(n >> (8 * i));
  }
  // A record: opcode, uint64 length filled in by endRecord.
  std::size_t beginRecord(Opcode op) {
    u8(static_cast<std::uint8_t>(op));
    u64(0);
    return out_.size();
  }
  void endRecord(std::size_t at) {
    const auto n = static_cast<std::uint64_t>(out_.size() - at);
    for (int i = 0; i < 8; ++i) out_[at - 8 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(n >> (8 * i));
  }

 private:
  void le(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  std::vector<std::uint8_t>& out_;
};

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> in) : in_(in) {}
  std::uint8_t u8() { return static_cast<std::uint8_t>(le(1)); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(le(2)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(le(4)); }
  std::uint64_t u64() { return le(8); }
  std::span<const std::uint8_t> take(std::uint64_t n) {
    need(n);
    auto s = in_.subspan(pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return s;
  }
  std::string string() {
    auto s = take(u32());
    return std::string(s.begin(), s.end());
  }
  StringMap map() {
    ByteReader m(take(u32()));
    StringMap out;
    while (!m.done()) {
      std::string k = m.string();
      out[k] = m.string();
    }
    return out;
  }
  std::span<const std::uint8_t> rest() { return take(left()); }
  std::size_t left() const { return in_.size() - pos_; }
  bool done() const { return pos_ == in_.size(); }
  std::size_t position() const { return pos_; }

 private:
  void need(std::uint64_t n) const {
    if (n > left())
      throw RecordError("field of " + std::to_string(n) + " bytes at offset " + std::to_string(pos_) + " overruns its record (" +
                        std::to_string(left()) + " bytes left)");
  }
  std::uint64_t le(int n) {
    need(static_cast<std::uint64_t>(n));
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(in_[pos_ + static_cast<std::size_t>(i)]) << (8 * i);
    pos_ += static_cast<std::size_t>(n);
    return v;
  }
  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
};

// Record encoders and decoders shared by the writer and the reader.
void writeSchema(ByteWriter& w, const Schema& s);
void writeChannel(ByteWriter& w, const Channel& c);
void writeMessage(ByteWriter& w, const Message& m);
void writeMetadata(ByteWriter& w, const Metadata& m);
Schema readSchema(ByteReader r);
Channel readChannel(ByteReader r);
Message readMessage(ByteReader r);
Metadata readMetadata(ByteReader r);

}  // namespace fusedet::drivers::mcap
