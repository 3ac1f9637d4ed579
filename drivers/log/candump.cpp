// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/log/candump.h"

#include <algorithm>
#include <stdexcept>

#include "fusedet/drivers/canopen/candump_log.h"
#include "fusedet/drivers/log/replay.h"

namespace fusedet::drivers::logs {

CanMessage toCanMessage(const canopen::CanFrame& f, std::string interface) {
  const std::size_t n = std::min<std::size_t>(f.len, 8);
  return CanMessage{f.stamp, std::move(interface), f.id, f.extended, f.rtr, f.error, {f.data.begin(), f.data.begin() + static_cast<long>(n)}};
}

canopen::CanFrame toCanFrame(const CanMessage& m) {
  canopen::CanFrame f;
  f.id = m.id;
  f.extended = m.extended;
  f.rtr = m.rtr;
  f.error = m.error;
  f.len = static_cast<std::uint8_t>(std::min<std::size_t>(m.data.size(), 8));
  std::copy_n(m.data.begin(), f.len, f.data.begin());
  f.stamp = m.stamp;
  return f;
}

std::uint64_t exportCandump(const std::filesystem::path& log, const std::filesystem::path& out) {
  LogSource source(log);
  canopen::CandumpWriter writer;
  bool opened = false;
  LogSource::Handlers h;
  h.can = [&](const CanMessage& m) {
    if (!opened) {  // the interface of the first frame names the log's bus
      if (auto r = writer.open(out.string(), m.interface.empty() ? "can0" : m.interface); !r)
        throw std::runtime_error(r.error().message());
      opened = true;
    }
    writer.write(toCanFrame(m));
  };
  while (source.step(h)) {
  }
  if (!opened)
    if (auto r = writer.open(out.string(), "can0"); !r) throw std::runtime_error(r.error().message());
  if (auto r = writer.close(); !r) throw std::runtime_error(r.error().message());
  return writer.lines();
}

}  // namespace fusedet::drivers::logs
