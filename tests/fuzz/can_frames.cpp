// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: CAN frames from the tilt motor's node as the master takes them - into the
// SDO client (expedited and segmented uploads, downloads, aborts, toggles, late answers) and the
// TPDO1 decoder - and each frame described as `fusedet tilt monitor` prints it. The input is a
// script: each step queues a transfer, advances the bus clock (timeouts), cancels, or delivers a
// frame (id, flags, length, data, stamp) from the input. Every transfer must complete exactly
// once with a result of a size its protocol allows; a decoded sample must carry the frame's
// position and statusword.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "byte_source.h"
#include "fusedet/drivers/canopen/can_frame.h"
#include "fusedet/drivers/canopen/frame_text.h"
#include "fusedet/drivers/canopen/inprocess_bus.h"
#include "fusedet/drivers/canopen/protocol.h"
#include "fusedet/drivers/canopen/sdo_client.h"
#include "fusedet/drivers/canopen/tilt_tpdo.h"

namespace {

using namespace fusedet::drivers::canopen;
constexpr int kNode = 5;

struct Transfer {
  bool upload = false;
  int completions = 0;
  std::size_t bytes = 0;
  bool ok = false;
};

CanFrame frameFrom(fusedet::fuzz::ByteSource& in) {
  CanFrame f;
  const std::uint8_t kind = in.byte();
  switch (kind % 4) {
    case 0: f.id = cob::kSdoTx + kNode; break;   // the node's SDO answers
    case 1: f.id = cob::kTpdo1 + kNode; break;   // its TPDO1
    case 2: f.id = in.get<std::uint16_t>() & 0x7FF; break;
    default: f.id = in.get<std::uint32_t>() & 0x1FFFFFFF; f.extended = true; break;
  }
  f.rtr = (kind & 0x10) != 0;
  f.error = (kind & 0x20) != 0;
  f.len = static_cast<std::uint8_t>(in.byte() % 9);
  in.fill(std::span<std::uint8_t>(f.data.data(), f.len));
  f.stamp = fusedet::Stamp{in.get<std::int64_t>()};
  return f;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fusedet::fuzz::ByteSource in(data, size);
  fusedet::Stamp clock{1'000'000'000};
  InProcessBus bus("fuzz0", [&clock] { return clock; });
  const auto endpoint = bus.connect();
  SdoClient sdo(*endpoint, kNode);
  TiltTpdoDecoder tpdo(kNode, TiltUnits{});
  std::vector<std::unique_ptr<Transfer>> transfers;
  auto track = [&](bool upload) {
    transfers.push_back(std::make_unique<Transfer>());
    Transfer* t = transfers.back().get();
    t->upload = upload;
    return [t](fusedet::Result<SdoClient::Bytes> r) {
      ++t->completions;
      t->ok = static_cast<bool>(r);
      if (r) t->bytes = r->size();
    };
  };
  for (int step = 0; step < 512 && !in.exhausted(); ++step) {
    const std::uint8_t op = in.byte();
    switch (op % 8) {
      case 0: sdo.upload(in.get<std::uint16_t>(), in.byte(), track(true)); break;
      case 1: {
        const std::uint16_t index = in.get<std::uint16_t>();
        const std::uint8_t sub = in.byte();
        const std::uint32_t value = in.get<std::uint32_t>();
        sdo.download(index, sub, value, in.byte() % 6, track(false));
        break;
      }
      case 2:
        clock = clock + static_cast<std::int64_t>(in.get<std::uint16_t>()) * 1'000'000;  // up to 65 s
        sdo.poll(clock);
        break;
      case 3:
        if (op & 0x80) sdo.cancelAll(fusedet::makeError(std::errc::host_unreachable, "node silent"));
        break;
      default: {
        const CanFrame f = frameFrom(in);
        (void)describeFrame(f);
        (void)describeErrorFrame(f);
        (void)sdo.onFrame(f);
        if (tpdo.isTpdo(f)) {
          const auto sample = tpdo.decode(f);
          if (f.len < 6) {
            if (sample) std::abort();
            break;
          }
          if (!sample) std::abort();
          const auto counts = static_cast<std::int32_t>(readLe(f.data, 0, 4));
          if (sample->sample.angle != TiltUnits{}.toRad(counts) || sample->statusword != readLe(f.data, 4, 2))
            std::abort();
          if (!std::isfinite(sample->sample.velocity) || sample->sample.stamp != f.stamp) std::abort();
        }
      }
    }
  }
  sdo.cancelAll(fusedet::makeError(std::errc::operation_canceled, "end of input"));
  if (!sdo.idle()) std::abort();
  for (const auto& t : transfers) {
    if (t->completions != 1) std::abort();
    if (t->ok && !t->upload && t->bytes != 0) std::abort();                  // a download answers nothing
    if (t->ok && t->upload && t->bytes > SdoClient::kMaxUpload + 7) std::abort();  // one segment past the limit at most
  }
  return 0;
}
