// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/lms291/lms291.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

namespace fusedet::drivers::lms291 {

namespace {

Error protocolError(const std::string& what) { return makeError(std::errc::protocol_error, what); }

std::string hex(std::uint8_t v) {
  char b[8];
  std::snprintf(b, sizeof b, "0x%02X", v);
  return b;
}

// Reply codes of a mode change (A0 RR): 00 ok, 01 bad password, 02 LMS fault.
Result<void> checkModeReply(const Telegram& t, std::uint8_t mode) {
  if (t.data.empty()) return protocolError("mode " + hex(mode) + ": empty reply");
  switch (t.data[0]) {
    case 0: return {};
    case 1: return protocolError("mode " + hex(mode) + " refused: bad password");
    case 2: return protocolError("mode " + hex(mode) + " refused: LMS fault");
    default: return protocolError("mode " + hex(mode) + " refused: reply code " + hex(t.data[0]));
  }
}

}  // namespace

std::string Lms291Config::validate() const {
  if (!baudMode(baud)) return "baud " + std::to_string(baud) + " is not one of 9600, 19200, 38400, 500000";
  if (!variant.valid())
    return "variant " + std::to_string(variant.angleDeg) + " deg / " + std::to_string(variant.resolutionCdeg / 100.0) +
           " deg is not supported (180/1, 180/0.5, 100/1, 100/0.5, 100/0.25)";
  if (remission && variant.resolutionCdeg != 100)
    return "remission needs 1 deg resolution: range+remission pairs of more beams exceed the 812-byte telegram";
  if (remission && interlaced) return "remission and interlaced output exclude each other";
  return {};
}

Lms291::Lms291(Lms291Config config) : config_(std::move(config)) {
  link_.setForceTermios2(config_.forceTermios2);
}

Lms291Counters Lms291::counters() const {
  Lms291Counters c = counters_;
  c.link = link_.counters();
  c.scans = decoder_.scans();
  c.lostScans = decoder_.lostScans();
  c.badScans = decoder_.badScans();
  return c;
}

RequestOptions Lms291::options(std::chrono::milliseconds replyTimeout) const {
  RequestOptions o;
  o.ackTimeout = config_.ackTimeout;
  // A streamed telegram in flight delays ACK and reply by up to its line time.
  const auto lineTime = std::chrono::milliseconds(
      static_cast<std::int64_t>(byteSeconds(std::max(link_.baud(), 1)) * kMaxTelegramSize * 1000) + 1);
  if (streaming_) o.ackTimeout += lineTime;
  o.replyTimeout = replyTimeout + lineTime;
  o.retries = stopping_ ? std::min(config_.retries, 1) : config_.retries;
  return o;
}

Result<void> Lms291::open() {
  if (const std::string why = config_.validate(); !why.empty()) return makeError(std::errc::invalid_argument, why);
  streaming_ = false;
  return link_.open(config_.device, 9600);
}

void Lms291::close() {
  link_.close();
  streaming_ = false;
}

Result<int> Lms291::detectBaud() {
  // The configured speed first (a restart after a crash finds the device there), then the
  // power-on speed, then the rest.
  std::vector<int> once{config_.baud, 9600};
  for (int b : kBauds)
    if (std::find(once.begin(), once.end(), b) == once.end()) once.push_back(b);
  // Two rounds: a device busy with something else (a reset, a long reply) gets a second chance.
  std::vector<int> order = once;
  order.insert(order.end(), once.begin(), once.end());
  for (int b : order) {
    if (auto r = link_.setBaud(b); !r) return r.error();
    RequestOptions o;
    // A device that streams at this speed answers after the telegram in flight.
    const auto lineTime = std::chrono::milliseconds(static_cast<std::int64_t>(byteSeconds(b) * kMaxTelegramSize * 1000) + 1);
    o.ackTimeout = config_.ackTimeout + lineTime;
    o.replyTimeout = config_.replyTimeout + lineTime;
    o.retries = 0;
    o.acceptAnyTelegram = true;  // streamed B0 telegrams prove the speed as well
    auto t = link_.request(static_cast<std::uint8_t>(Command::kStatus), {}, o);
    if (t) {
      streaming_ = t->command != (static_cast<std::uint8_t>(Command::kStatus) | kReplyBit);
      spdlog::debug("lms291 {}: device answers at {} baud{}", config_.device, b, streaming_ ? " (streaming)" : "");
      return b;
    }
    if (t.error().code == std::errc::no_such_device) return t.error();
  }
  return makeError(std::errc::timed_out, config_.device + ": no LMS answers at 9600, 19200, 38400 or 500000 baud");
}

Result<void> Lms291::setMode(Mode mode, std::span<const std::uint8_t> params) {
  std::vector<std::uint8_t> data{static_cast<std::uint8_t>(mode)};
  data.insert(data.end(), params.begin(), params.end());
  auto t = link_.request(static_cast<std::uint8_t>(Command::kSwitchMode), data, options(config_.modeTimeout));
  if (!t) return t.error();
  if (t->status) noteStatus(*t->status);
  if (auto r = checkModeReply(*t, static_cast<std::uint8_t>(mode)); !r) return r;
  if (mode == Mode::kMonitoring || mode == Mode::kInstallation) streaming_ = false;
  if (mode == Mode::kStreamAll || mode == Mode::kStreamPartial || mode == Mode::kStreamRemission) streaming_ = true;
  return {};
}

Result<void> Lms291::switchBaud(int baud) {
  const auto mode = baudMode(baud);
  if (!mode) return makeError(std::errc::invalid_argument, "unsupported baud " + std::to_string(baud));
  if (link_.baud() == baud) return {};
  // The reply comes at the old speed; only then does the host follow (§3).
  if (auto r = setMode(*mode); !r) return r;
  link_.drain();
  if (auto r = link_.setBaud(baud); !r) return r;
  std::this_thread::sleep_for(config_.baudSwitchPause);
  link_.flushInput();
  auto s = queryStatus();
  if (!s) return Error{s.error().code, "verify " + std::to_string(baud) + " baud: " + s.error().message()};
  // The answer proves the speed; the baud word's offset is disputed (115 vs 116), so only log.
  if (s->baud != baud)
    spdlog::debug("lms291 {}: status reports {} baud after switching to {}", config_.device, s->baud.value_or(0), baud);
  return {};
}

Result<std::string> Lms291::queryType() {
  auto t = link_.request(static_cast<std::uint8_t>(Command::kType), {}, options(config_.replyTimeout));
  if (!t) return t.error();
  std::string type;
  for (std::uint8_t c : t->data)
    if (c >= 0x20 && c < 0x7F) type.push_back(static_cast<char>(c));
  while (!type.empty() && type.back() == ' ') type.pop_back();
  return type;
}

Result<DeviceStatus> Lms291::queryStatus() {
  auto t = link_.request(static_cast<std::uint8_t>(Command::kStatus), {}, options(config_.replyTimeout));
  if (!t) return t.error();
  if (t->status) noteStatus(*t->status);
  return decodeStatus(t->data);
}

Result<ConfigBlock> Lms291::readConfig() {
  auto t = link_.request(static_cast<std::uint8_t>(Command::kReadConfig), {}, options(config_.replyTimeout));
  if (!t) return t.error();
  return decodeConfig(t->data);
}

Result<void> Lms291::writeConfig(const ConfigBlock& config) {
  // Writing needs installation mode (password), and monitoring mode afterwards (§3).
  const std::string password = kInstallPassword;
  if (auto r = setMode(Mode::kInstallation, std::span(reinterpret_cast<const std::uint8_t*>(password.data()), password.size())); !r)
    return r;
  auto t = link_.request(static_cast<std::uint8_t>(Command::kWriteConfig), config.bytes, options(config_.configTimeout));
  if (!t) return t.error();
  if (t->data.empty() || t->data[0] != 1) return protocolError("configuration refused by the device");
  return setMode(Mode::kMonitoring);
}

Result<void> Lms291::setVariant(Variant v) {
  auto t = link_.request(static_cast<std::uint8_t>(Command::kSetVariant), variantPayload(v), options(config_.replyTimeout));
  if (!t) return t.error();
  if (t->data.size() < 5 || t->data[0] != 1)
    return protocolError("variant " + std::to_string(v.angleDeg) + "/" + std::to_string(v.resolutionCdeg) +
                         " refused by the device");
  return {};
}

Result<DeviceInfo> Lms291::start() {
  DeviceInfo info;
  if (auto r = open(); !r) return r.error();
  auto found = detectBaud();
  if (!found) return found.error();
  info.foundBaud = *found;
  if (streaming_)
    if (auto r = setMode(Mode::kMonitoring); !r) return r.error();
  // Switch first: everything after goes faster.
  if (auto r = switchBaud(config_.baud); !r) return r.error();
  auto type = queryType();
  if (!type) return type.error();
  info.type = *type;
  // LMS Fast (S14): fixed 90 deg at 0.5 deg, no variants, reflectivity as C4 - not modelled here.
  if (info.type.find("S14") != std::string::npos)
    return makeError(std::errc::not_supported, info.type + " (LMS Fast, fixed 90 deg) is not supported by this driver");

  auto cfg = readConfig();
  if (!cfg) return cfg.error();
  ConfigBlock wanted = *cfg;
  wanted.bytes[5] = config_.remission ? kMeasuringRemission : config_.measuringMode;
  wanted.bytes[6] = config_.unit == Unit::kMm ? 1 : 0;
  wanted.bytes[4] = static_cast<std::uint8_t>(config_.realTimeIndices ? (wanted.bytes[4] | 0x02) : (wanted.bytes[4] & ~0x02));
  if (wanted.bytes != cfg->bytes) {
    // The configuration lives in EEPROM: write only what changed.
    if (auto r = writeConfig(wanted); !r) return r.error();
  }

  if (auto r = setVariant(config_.variant); !r) return r.error();
  auto status = queryStatus();
  if (!status) return status.error();
  info.status = *status;
  if (status->angleDeg != config_.variant.angleDeg || status->resolutionCdeg != config_.variant.resolutionCdeg)
    return protocolError("device reports " + std::to_string(status->angleDeg) + " deg / " +
                         std::to_string(status->resolutionCdeg) + " cdeg after setting the variant");
  decoder_.reset(config_.variant, config_.remission, wanted.bytes[5], config_.unit);

  if (config_.remission) {
    std::vector<std::uint8_t> params;
    putU16(params, 1);  // one subrange: all beams
    putU16(params, 1);
    putU16(params, static_cast<std::uint16_t>(config_.variant.beams()));
    if (auto r = setMode(Mode::kStreamRemission, params); !r) return r.error();
  } else {
    if (auto r = setMode(config_.interlaced ? Mode::kStreamPartial : Mode::kStreamAll); !r) return r.error();
  }
  ++counters_.inits;
  spdlog::info("lms291 {}: {} streaming at {} baud ({} deg / {} deg, mm{})", config_.device, info.type, config_.baud,
               config_.variant.angleDeg, config_.variant.resolutionCdeg / 100.0,
               config_.remission ? ", remission" : "");
  return info;
}

Result<void> Lms291::stop() {
  if (!link_.isOpen()) return {};
  // Best effort and bounded: a device that does not answer must not hold up a shutdown.
  stopping_ = true;
  struct Reset {
    bool& flag;
    ~Reset() { flag = false; }
  } reset{stopping_};
  Result<void> first;
  if (auto r = setMode(Mode::kMonitoring); !r) first = r;
  if (auto r = switchBaud(9600); !r && first) first = r;
  link_.close();
  streaming_ = false;
  return first;
}

void Lms291::noteStatus(std::uint8_t status) {
  const StatusByte s{status};
  if (s.needsAttention()) {
    ++counters_.statusWarnings;
    if (s.raw != lastStatus_.raw) spdlog::warn("lms291 {}: status {} ({})", config_.device, hex(s.raw), s.describe());
  } else if (lastStatus_.needsAttention()) {
    spdlog::info("lms291 {}: status back to {} ({})", config_.device, hex(s.raw), s.describe());
  }
  lastStatus_ = s;
}

std::optional<LaserScan> Lms291::handle(const Telegram& t) {
  if (t.status) noteStatus(*t.status);
  return decoder_.decode(t, link_.baud());
}

Result<LaserScan> Lms291::readScan(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::microseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return makeError(std::errc::timed_out, config_.device + ": no scan within " + std::to_string(timeout.count()) + " ms");
    auto t = link_.receive(left);
    if (!t) return t.error();
    if (auto scan = handle(*t)) return std::move(*scan);
  }
}

}  // namespace fusedet::drivers::lms291
