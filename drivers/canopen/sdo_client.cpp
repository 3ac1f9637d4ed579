// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/canopen/sdo_client.h"

#include <cstdio>

#include "fusedet/drivers/canopen/protocol.h"

namespace fusedet::drivers::canopen {

namespace {
class SdoAbortCategory : public std::error_category {
 public:
  const char* name() const noexcept override { return "sdo-abort"; }
  std::string message(int code) const override { return "SDO abort " + abortCodeText(static_cast<std::uint32_t>(code)); }
};
}  // namespace

const std::error_category& sdoAbortCategory() {
  static SdoAbortCategory category;
  return category;
}

std::string SdoClient::what(const Transfer& t) const {
  char buf[64];
  std::snprintf(buf, sizeof buf, "SDO %s 0x%04X:%02X node %d", t.upload ? "upload" : "download", t.index, t.sub, node_);
  return buf;
}

Error SdoClient::abortError(std::uint32_t code, const Transfer& t) const {
  return Error{std::error_code(static_cast<int>(code), sdoAbortCategory()), what(t)};
}

void SdoClient::download(std::uint16_t index, std::uint8_t sub, std::uint32_t value, int bytes, Done done) {
  Transfer t;
  t.index = index;
  t.sub = sub;
  t.value = value;
  t.bytes = bytes < 1 ? 1 : (bytes > 4 ? 4 : bytes);
  t.done = std::move(done);
  queue_.push_back(std::move(t));
  if (queue_.size() == 1) startNext();
}

void SdoClient::upload(std::uint16_t index, std::uint8_t sub, Done done) {
  Transfer t;
  t.upload = true;
  t.index = index;
  t.sub = sub;
  t.done = std::move(done);
  queue_.push_back(std::move(t));
  if (queue_.size() == 1) startNext();
}

void SdoClient::sendRequest(const CanFrame& f) {
  Transfer& t = queue_.front();
  t.deadline = bus_.now() + std::chrono::nanoseconds(timeout_).count();
  if (auto r = bus_.send(f); !r) {
    ++counters_.sendErrors;
    finish(Error{r.error().code, what(t) + ": " + r.error().context});
  }
}

void SdoClient::startNext() {
  while (!queue_.empty() && !queue_.front().started) {
    Transfer& t = queue_.front();
    t.started = true;
    CanFrame f = CanFrame::make(cob::kSdoRx + static_cast<std::uint32_t>(node_), {0, 0, 0, 0, 0, 0, 0, 0});
    f.data[0] = t.upload ? sdo::kUploadRequest : sdo::downloadCommand(t.bytes);
    writeLe(f.data, 1, t.index, 2);
    f.data[3] = t.sub;
    if (!t.upload) writeLe(f.data, 4, t.value, t.bytes);
    const std::size_t before = queue_.size();
    sendRequest(f);
    if (queue_.size() == before) return;  // sent; wait for the response
  }
}

void SdoClient::finish(Result<Bytes> r) {
  Transfer t = std::move(queue_.front());
  queue_.pop_front();
  if (r) ++counters_.transfers;
  // The callback may queue new transfers; start the next one after it ran.
  if (t.done) t.done(std::move(r));
  if (!queue_.empty() && !queue_.front().started) startNext();
}

bool SdoClient::onFrame(const CanFrame& f) {
  if (f.error || f.rtr || f.extended || f.id != cob::kSdoTx + static_cast<std::uint32_t>(node_)) return false;
  if (queue_.empty() || !queue_.front().started) return true;  // a late response: ours, but stale
  Transfer& t = queue_.front();
  if (f.len < 8) {
    finish(makeError(std::errc::protocol_error, what(t) + ": short SDO response"));
    return true;
  }
  const std::uint8_t cmd = f.data[0];
  const bool sameObject = readLe(f.data, 1, 2) == t.index && f.data[3] == t.sub;
  if (cmd == sdo::kAbort) {
    if (!sameObject && !t.segmented) return true;  // abort of an older transfer
    ++counters_.aborts;
    finish(abortError(readLe(f.data, 4, 4), t));
    return true;
  }
  if (!t.upload) {
    if (cmd == sdo::kDownloadResponse && sameObject) finish(Bytes{});
    return true;
  }
  if (!t.segmented) {
    if ((cmd & 0xE0) != 0x40 || !sameObject) return true;  // not an initiate-upload response
    if (cmd & 0x02) {  // expedited: 4 - n bytes, n in bits 2..3 when bit 0 (size indicated) is set
      int n = (cmd & 0x01) ? 4 - ((cmd >> 2) & 0x03) : 4;
      finish(Bytes(f.data.begin() + 4, f.data.begin() + 4 + n));
      return true;
    }
    // Segmented: bytes 4..7 = total size when bit 0 is set.
    t.segmented = true;
    t.toggle = false;
    CanFrame req = CanFrame::make(cob::kSdoRx + static_cast<std::uint32_t>(node_), {sdo::kUploadSegmentRequest, 0, 0, 0, 0, 0, 0, 0});
    sendRequest(req);
    return true;
  }
  // Upload segment response: 000t nnnc.
  if ((cmd & 0xE0) != 0x00) {
    finish(makeError(std::errc::protocol_error, what(t) + ": unexpected command in a segmented upload"));
    return true;
  }
  if (((cmd >> 4) & 1) != static_cast<int>(t.toggle)) {
    (void)bus_.send(sdoAbortFrame(cob::kSdoRx + static_cast<std::uint32_t>(node_), t.index, t.sub, abortcode::kToggleBit));
    finish(abortError(abortcode::kToggleBit, t));
    return true;
  }
  const int n = 7 - ((cmd >> 1) & 0x07);
  t.data.insert(t.data.end(), f.data.begin() + 1, f.data.begin() + 1 + n);
  if (cmd & 0x01) {
    finish(std::move(t.data));
    return true;
  }
  if (t.data.size() > kMaxUpload) {
    finish(makeError(std::errc::value_too_large, what(t) + ": segmented upload longer than 4096 bytes"));
    return true;
  }
  t.toggle = !t.toggle;
  CanFrame req = CanFrame::make(cob::kSdoRx + static_cast<std::uint32_t>(node_),
                                {static_cast<std::uint8_t>(sdo::kUploadSegmentRequest | (t.toggle ? 0x10 : 0)), 0, 0, 0, 0, 0, 0, 0});
  sendRequest(req);
  return true;
}

void SdoClient::poll(Stamp now) {
  if (queue_.empty() || !queue_.front().started || now < queue_.front().deadline) return;
  Transfer& t = queue_.front();
  ++counters_.timeouts;
  // Tell the server to give up too, so a late response is not taken for the next transfer.
  (void)bus_.send(sdoAbortFrame(cob::kSdoRx + static_cast<std::uint32_t>(node_), t.index, t.sub, abortcode::kTimeout));
  finish(makeError(std::errc::timed_out, what(t) + ": no response"));
}

void SdoClient::cancelAll(const Error& why) {
  std::deque<Transfer> q = std::move(queue_);
  queue_.clear();
  for (Transfer& t : q)
    if (t.done) t.done(Error{why.code, what(t) + ": " + why.message()});
}

}  // namespace fusedet::drivers::canopen
