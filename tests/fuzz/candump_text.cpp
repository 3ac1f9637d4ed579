// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: candump -l text (can-utils' log format, the tilt motor's recordings) as
// readCandumpLog reads a file and parseCandumpLine takes each line. Bad lines may only be
// refused with a message; an accepted line is a valid frame whose formatted line reads back to
// the same frame, interface and stamp (to the microsecond the format keeps).

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "fusedet/drivers/canopen/candump_log.h"
#include "memory_file.h"

namespace {

using namespace fusedet::drivers::canopen;

void checkLine(std::string_view line) {
  const auto entry = parseCandumpLine(line);
  if (!entry) {
    if (entry.error().message().empty()) std::abort();  // a refusal says why
    return;
  }
  const CanFrame& f = entry->frame;
  if (f.len > 8 || f.stamp.ns < 0) std::abort();
  if (f.id > (f.extended || f.error ? 0x1FFFFFFFu : 0x7FFu)) std::abort();
  const auto again = parseCandumpLine(formatCandumpLine(f, entry->interface));
  if (!again || !again->frame.sameContent(f) || again->interface != entry->interface) std::abort();
  if (again->frame.stamp.ns != f.stamp.ns / 1000 * 1000) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (std::size_t start = 0; start < text.size();) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    checkLine(text.substr(start, end - start));
    start = end + 1;
  }
  const fusedet::fuzz::MemoryFile file(data, size);
  if (!file.ok()) return 0;
  const auto log = readCandumpLog(file.path());
  if (!log && log.error().message().find(file.path()) == std::string::npos) std::abort();  // names the file
  if (log)
    for (const CandumpEntry& e : *log)
      if (e.frame.len > 8) std::abort();
  return 0;
}
