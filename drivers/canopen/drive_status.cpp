// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/canopen/drive_status.h"

#include "fusedet/drivers/canopen/sdo_client.h"

namespace fusedet::drivers::canopen {

Result<DriveStatusReport> queryDriveStatus(CanBus& bus, int node, std::chrono::milliseconds sdoTimeout) {
  SdoClient sdo(bus, node, sdoTimeout);
  DriveStatusReport r;
  std::optional<Error> failure;
  int pending = 0;
  auto read = [&](std::uint16_t index, std::uint8_t sub, std::function<void(const SdoClient::Bytes&)> use) {
    ++pending;
    sdo.upload(index, sub, [&, use](Result<SdoClient::Bytes> b) {
      --pending;
      if (!b) {
        if (!failure) failure = b.error();
        return;
      }
      use(*b);
    });
  };
  auto le = [](const SdoClient::Bytes& b) { return b.empty() ? 0u : readLe(b, 0, static_cast<int>(std::min<std::size_t>(b.size(), 4))); };
  read(od::kDeviceType, 0, [&](const SdoClient::Bytes& b) { r.deviceType = le(b); });
  read(od::kDeviceName, 0, [&](const SdoClient::Bytes& b) { r.deviceName.assign(b.begin(), b.end()); });
  read(od::kStatusword, 0, [&](const SdoClient::Bytes& b) {
    r.statusword = static_cast<std::uint16_t>(le(b));
    r.state = decodeStatusword(r.statusword);
  });
  read(od::kModeDisplay, 0, [&](const SdoClient::Bytes& b) { r.mode = static_cast<std::int8_t>(le(b)); });
  read(od::kPositionActual, 0, [&](const SdoClient::Bytes& b) { r.position = static_cast<std::int32_t>(le(b)); });
  read(od::kErrorCode, 0, [&](const SdoClient::Bytes& b) { r.errorCode = static_cast<std::uint16_t>(le(b)); });
  read(od::kHeartbeatProducer, 0, [&](const SdoClient::Bytes& b) { r.heartbeatMs = static_cast<std::uint16_t>(le(b)); });
  while (pending > 0 && !failure) {
    auto f = bus.receive(std::chrono::milliseconds(5));
    if (f) {
      if (!sdo.onFrame(*f) && f->id == cob::kHeartbeat + static_cast<std::uint32_t>(node) && f->len >= 1)
        r.nmt = parseNmtState(f->data[0]);
    } else if (f.error().code != std::errc::timed_out) {
      return f.error();
    }
    sdo.poll(bus.now());
  }
  if (failure) return *failure;
  return r;
}

}  // namespace fusedet::drivers::canopen
