// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/canopen/candump_log.h"

#include <cerrno>
#include <fstream>

namespace fusedet::drivers::canopen {

namespace {

int hexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Bad content is not a system error: the message is the whole story ("file:line: what").
Error bad(std::string what) { return Error{std::error_code(), std::move(what)}; }

}  // namespace

std::string formatCandumpLine(const CanFrame& f, std::string_view interface) {
  std::int64_t ns = f.stamp.ns < 0 ? 0 : f.stamp.ns;
  char stamp[48];
  std::snprintf(stamp, sizeof stamp, "(%010lld.%06lld) ", static_cast<long long>(ns / 1'000'000'000),
                static_cast<long long>((ns % 1'000'000'000) / 1000));
  std::string line = stamp;
  line += interface;
  line += ' ';
  line += f.toString();
  line += '\n';
  return line;
}

Result<CandumpEntry> parseCandumpLine(std::string_view s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.remove_suffix(1);
  CandumpEntry e;
  // "(seconds.fraction)"
  if (s.empty() || s.front() != '(') return bad("expected '(' and a time stamp");
  std::size_t close = s.find(')');
  if (close == std::string_view::npos) return bad("time stamp without ')'");
  std::string_view ts = s.substr(1, close - 1);
  std::size_t dot = ts.find('.');
  if (dot == std::string_view::npos || dot == 0 || dot + 1 >= ts.size() || dot > 12 || ts.size() - dot - 1 > 9)
    return bad("time stamp is not seconds.fraction");
  std::int64_t sec = 0, frac = 0, scale = 1'000'000'000;
  for (std::size_t i = 0; i < ts.size(); ++i) {
    if (i == dot) continue;
    if (ts[i] < '0' || ts[i] > '9') return bad("time stamp has a non-digit");
    if (i < dot) {
      sec = sec * 10 + (ts[i] - '0');
    } else {
      frac = frac * 10 + (ts[i] - '0');
      scale /= 10;
    }
  }
  // Twelve digits of seconds fit an int64 but their nanoseconds may not (the limit is
  // 9223372036.854775807 s, year 2262): refuse rather than overflow.
  std::int64_t ns = 0;
  if (__builtin_mul_overflow(sec, std::int64_t{1'000'000'000}, &ns) || __builtin_add_overflow(ns, frac * scale, &ns))
    return bad("time stamp beyond 9223372036.854775807 s (64-bit nanoseconds)");
  e.frame.stamp = Stamp{ns};
  s.remove_prefix(close + 1);
  // " interface "
  if (s.empty() || s.front() != ' ') return bad("expected a space after the time stamp");
  s.remove_prefix(1);
  std::size_t space = s.find(' ');
  if (space == 0 || space == std::string_view::npos || space > 15) return bad("expected an interface name and a space");
  e.interface = std::string(s.substr(0, space));
  s.remove_prefix(space + 1);
  // "ID#DATA"
  std::size_t hash = s.find('#');
  if (hash == std::string_view::npos) return bad("frame without '#'");
  if (hash != 3 && hash != 8) return bad("CAN id must have 3 or 8 hex digits");
  std::uint32_t id = 0;
  for (std::size_t i = 0; i < hash; ++i) {
    int d = hexDigit(s[i]);
    if (d < 0) return bad("CAN id is not hex");
    id = (id << 4) | static_cast<std::uint32_t>(d);
  }
  CanFrame& f = e.frame;
  if (hash == 8) {
    if (id & 0x20000000u) {
      f.error = true;
      f.id = id & 0x1FFFFFFFu;
    } else {
      if (id > 0x1FFFFFFFu) return bad("29-bit CAN id out of range");
      f.extended = true;
      f.id = id;
    }
  } else {
    if (id > 0x7FF) return bad("11-bit CAN id out of range");
    f.id = id;
  }
  std::string_view data = s.substr(hash + 1);
  if (!data.empty() && data.front() == '#') return bad("CAN FD frame (##) not supported");
  if (!data.empty() && (data.front() == 'R' || data.front() == 'r')) {
    if (f.error) return bad("error frame cannot be a remote request");
    f.rtr = true;
    if (data.size() == 2 && data[1] >= '0' && data[1] <= '8') f.len = static_cast<std::uint8_t>(data[1] - '0');
    else if (data.size() != 1) return bad("remote request length must be one digit 0..8");
    return e;
  }
  std::size_t n = 0;
  for (std::size_t i = 0; i < data.size();) {
    if (data[i] == '.') {  // candump accepts dots between bytes
      ++i;
      continue;
    }
    if (i + 1 >= data.size()) return bad("odd number of hex digits in the data");
    int hi = hexDigit(data[i]), lo = hexDigit(data[i + 1]);
    if (hi < 0 || lo < 0) return bad("data is not hex");
    if (n == 8) return bad("more than 8 data bytes");
    f.data[n++] = static_cast<std::uint8_t>(hi << 4 | lo);
    i += 2;
  }
  f.len = static_cast<std::uint8_t>(n);
  return e;
}

Result<std::vector<CandumpEntry>> readCandumpLog(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return errnoError(errno ? errno : ENOENT, path + ": cannot open");
  std::vector<CandumpEntry> out;
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line == "\r") continue;
    if (line.size() > 256) return bad(path + ":" + std::to_string(number) + ": line too long for a CAN frame");
    auto e = parseCandumpLine(line);
    if (!e) return bad(path + ":" + std::to_string(number) + ": " + e.error().message());
    out.push_back(std::move(*e));
  }
  if (in.bad()) return errnoError(EIO, path + ": read error");
  return out;
}

Result<void> CandumpWriter::open(const std::string& path, std::string interface) {
  (void)close();
  file_ = std::fopen(path.c_str(), "w");
  if (!file_) return errnoError(errno, path + ": cannot create");
  path_ = path;
  interface_ = std::move(interface);
  lines_ = 0;
  failed_ = false;
  return {};
}

void CandumpWriter::write(const CanFrame& f) {
  if (!file_) return;
  std::string line = formatCandumpLine(f, interface_);
  if (std::fwrite(line.data(), 1, line.size(), file_) != line.size()) failed_ = true;
  ++lines_;
}

Result<void> CandumpWriter::close() {
  if (!file_) return {};
  bool ok = std::fclose(file_) == 0 && !failed_;
  file_ = nullptr;
  if (!ok) return errnoError(EIO, path_ + ": write error");
  return {};
}

}  // namespace fusedet::drivers::canopen
