// SPDX-License-Identifier: Apache-2.0
#pragma once
// What `fusedet log info` reports about a sensor log: per channel the message count, time span,
// rate and gaps; for the file its chunks, metadata and every kind of damage the reader found
// (truncation point, damaged chunks, summary mismatches).

#include <cstdint>
#include <string>
#include <vector>

#include "fusedet/drivers/log/mcap_reader.h"

namespace fusedet::drivers::logs {

struct ChannelInfo {
  std::string topic, schema;
  std::uint64_t messages = 0;
  std::uint64_t first = 0, last = 0;  // log times [ns]
  double usualPeriodS = 0;
  double maxGapS = 0;
  std::uint64_t gaps = 0;  // intervals longer than gapFactor x the usual period
};

struct LogInfo {
  std::uint64_t fileSize = 0;
  std::uint64_t messages = 0, start = 0, end = 0;
  std::size_t chunks = 0, damagedChunks = 0;
  std::vector<ChannelInfo> channels;
  std::vector<std::string> metadata;  // record names
  bool intact = false;
  std::string truncation;             // empty when the file is whole
  std::vector<std::string> problems;
};

// Reads every intact chunk once. gapFactor: an interval counts as a gap above gapFactor x the usual
// period (the 90th percentile of the intervals: bursts do not make every pause a gap).
LogInfo inspectLog(const mcap::McapReader& reader, double gapFactor = 3.0);
// Human-readable report (what `fusedet log info` prints).
std::string formatLogInfo(const LogInfo& info, const std::string& name);

}  // namespace fusedet::drivers::logs
