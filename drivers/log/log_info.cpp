// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/log/log_info.h"

#include <algorithm>
#include <cstdio>
#include <map>

namespace fusedet::drivers::logs {

LogInfo inspectLog(const mcap::McapReader& reader, double gapFactor) {
  const mcap::LogIndex& x = reader.index();
  LogInfo info;
  info.fileSize = x.fileSize;
  info.messages = x.messages;
  info.start = x.start;
  info.end = x.end;
  info.chunks = x.chunks.size();
  info.damagedChunks = x.chunks.size() - x.goodChunks();
  info.intact = x.intact();
  if (x.truncation) info.truncation = x.truncation->describe();
  info.problems = x.problems;
  for (const auto& m : x.metadata) info.metadata.push_back(m.name);

  std::map<std::uint16_t, std::vector<std::uint64_t>> times;
  for (std::size_t i = 0; i < x.chunks.size(); ++i) {
    if (!x.chunks[i].ok) continue;
    for (const mcap::Message& m : reader.chunkMessages(i)) times[m.channelId].push_back(m.logTime);
  }
  for (const mcap::Message& m : x.looseMessages) times[m.channelId].push_back(m.logTime);
  for (const auto& [id, channel] : x.channels) {
    ChannelInfo c;
    c.topic = channel.topic;
    if (auto s = x.schemas.find(channel.schemaId); s != x.schemas.end()) c.schema = s->second.name;
    std::vector<std::uint64_t>& t = times[id];
    std::sort(t.begin(), t.end());
    c.messages = t.size();
    if (!t.empty()) c.first = t.front(), c.last = t.back();
    if (t.size() >= 2) {
      std::vector<double> periods;
      for (std::size_t i = 1; i < t.size(); ++i) periods.push_back(static_cast<double>(t[i] - t[i - 1]) * 1e-9);
      // Bursty streams (a telegram in several reads, SYNC + TPDO in the same millisecond) have a
      // tiny median interval: the usual pause between bursts is the 90th percentile.
      std::vector<double> sorted = periods;
      const std::size_t p90 = sorted.size() * 9 / 10;
      std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(p90), sorted.end());
      c.usualPeriodS = sorted[p90];
      c.maxGapS = *std::max_element(periods.begin(), periods.end());
      for (double p : periods)
        if (p > gapFactor * c.usualPeriodS && p > 1e-3) ++c.gaps;
    }
    info.channels.push_back(std::move(c));
  }
  return info;
}

std::string formatLogInfo(const LogInfo& info, const std::string& name) {
  std::string out;
  char line[512];
  const double span = info.messages ? static_cast<double>(info.end - info.start) * 1e-9 : 0;
  std::snprintf(line, sizeof line, "file      %s (%llu bytes)\nstate     %s\nmessages  %llu in %zu chunks (%zu damaged)\n",
                name.c_str(), static_cast<unsigned long long>(info.fileSize),
                info.intact ? "intact (summary and footer check out)" : "DAMAGED", static_cast<unsigned long long>(info.messages),
                info.chunks, info.damagedChunks);
  out += line;
  std::snprintf(line, sizeof line, "time      %.9f .. %.9f s (%.3f s)\n", static_cast<double>(info.start) * 1e-9,
                static_cast<double>(info.end) * 1e-9, span);
  out += line;
  if (!info.truncation.empty()) out += "truncated " + info.truncation + "\n";
  for (const std::string& p : info.problems) out += "problem   " + p + "\n";
  out += "metadata ";
  for (const std::string& m : info.metadata) out += " " + m;
  out += info.metadata.empty() ? " none\n" : "\n";
  std::snprintf(line, sizeof line, "%-20s %-26s %9s %10s %9s %9s %5s\n", "topic", "schema", "messages", "span_s", "rate_hz",
                "max_gap_s", "gaps");
  out += line;
  for (const ChannelInfo& c : info.channels) {
    const double cspan = static_cast<double>(c.last - c.first) * 1e-9;
    std::snprintf(line, sizeof line, "%-20s %-26s %9llu %10.3f %9.2f %9.4f %5llu\n", c.topic.c_str(), c.schema.c_str(),
                  static_cast<unsigned long long>(c.messages), cspan,
                  cspan > 0 ? static_cast<double>(c.messages - 1) / cspan : 0.0, c.maxGapS, static_cast<unsigned long long>(c.gaps));
    out += line;
  }
  return out;
}

}  // namespace fusedet::drivers::logs
