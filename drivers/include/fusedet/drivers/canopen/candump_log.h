// SPDX-License-Identifier: Apache-2.0
#pragma once
// The can-utils `candump -l` log format, one frame a line:
//   (1700000000.123456) can0 123#DEADBEEF      11-bit id, data in hex
//   (1700000000.123457) can0 12345678#R        29-bit id (8 hex digits), remote request [R0..R8]
//   (1700000000.123458) can0 20000040#0000000000000000   error frame (CAN_ERR_FLAG in the id)
// Written so that can-utils (log2asc, canplayer) and python-can read it. We write our
// CLOCK_MONOTONIC stamps (candump writes wall-clock time; the tools only use differences).

#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "fusedet/core/result.h"
#include "fusedet/drivers/canopen/can_frame.h"

namespace fusedet::drivers::canopen {

struct CandumpEntry {
  CanFrame frame;  // frame.stamp = the line's time stamp
  std::string interface;
};

std::string formatCandumpLine(const CanFrame& f, std::string_view interface);
// One line (without or with its '\n'). Errors name what is wrong: bad stamp, bad id, odd hex,
// more than 8 bytes, CAN FD ("##", not supported), trailing garbage.
Result<CandumpEntry> parseCandumpLine(std::string_view line);

// Reads a whole log; the first bad line ends it with an error naming the file and line number.
// Empty lines are skipped.
Result<std::vector<CandumpEntry>> readCandumpLog(const std::string& path);

// Appends lines to a file (flushed on close; each line is written whole).
class CandumpWriter {
 public:
  CandumpWriter() = default;
  ~CandumpWriter() { (void)close(); }
  CandumpWriter(const CandumpWriter&) = delete;
  CandumpWriter& operator=(const CandumpWriter&) = delete;
  Result<void> open(const std::string& path, std::string interface);
  void write(const CanFrame& f);
  Result<void> close();  // flushes; reports a write error that happened on any line
  std::uint64_t lines() const { return lines_; }

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
  std::string interface_;
  std::uint64_t lines_ = 0;
  bool failed_ = false;
};

}  // namespace fusedet::drivers::canopen
