// SPDX-License-Identifier: Apache-2.0
// fusedet lms: talk to a SICK LMS 291 (or lms291-sim) and decode captured telegram streams.
//   probe DEVICE   find the speed, print type, status and configuration (changes nothing)
//   stream DEVICE  initialise, stream scans (reconnecting), stop (device back to 9600 baud)
//   decode FILE    one JSON object per telegram found in a raw byte capture

#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <thread>

#include "command.h"
#include "fusedet/drivers/lms291/lms291.h"
#include "fusedet/drivers/lms291/scan_stream.h"

namespace fusedet::tools {
namespace {

using namespace drivers::lms291;

std::atomic<bool> gInterrupted{false};
extern "C" void onSignal(int) { gInterrupted = true; }

struct LmsOptions {
  std::string device;
  std::string file;
  int baud = 38400;
  int angle = 180;
  double resolution = 0.5;
  bool remission = false;
  bool interlaced = false;
  bool realTimeIndices = false;
  bool termios2 = false;
  long count = 0;
  double duration = 0;
  bool json = false;
  int pauseMs = 250;
  std::string record;  // raw bytes read from the port, for `decode`
};

Lms291Config toConfig(const LmsOptions& o) {
  Lms291Config c;
  c.device = o.device;
  c.baud = o.baud;
  c.variant = Variant{o.angle, static_cast<int>(std::lround(o.resolution * 100))};
  c.remission = o.remission;
  c.interlaced = o.interlaced;
  c.realTimeIndices = o.realTimeIndices;
  c.forceTermios2 = o.termios2;
  c.baudSwitchPause = std::chrono::milliseconds(o.pauseMs);
  if (const std::string why = c.validate(); !why.empty()) throw std::runtime_error(why);
  return c;
}

int runProbe(const LmsOptions& o) {
  Lms291 lms(toConfig(o));
  if (auto r = lms.open(); !r) throw std::runtime_error(r.error().message());
  auto baud = lms.detectBaud();
  if (!baud) throw std::runtime_error(baud.error().message());
  std::printf("device   %s\nbaud     %d%s\n", o.device.c_str(), *baud, lms.streaming() ? " (was streaming)" : "");
  if (lms.streaming())
    if (auto r = lms.setMode(Mode::kMonitoring); !r) throw std::runtime_error(r.error().message());
  auto type = lms.queryType();
  if (!type) throw std::runtime_error("type query: " + type.error().message());
  auto status = lms.queryStatus();
  if (!status) throw std::runtime_error("status query: " + status.error().message());
  auto cfg = lms.readConfig();
  if (!cfg) throw std::runtime_error("configuration: " + cfg.error().message());
  std::printf("type     %s\nfirmware %s\nmode     0x%02X\nvariant  %d deg / %.2f deg\nunit     %s\n",
              type->c_str(), status->firmware.c_str(), status->operatingMode, status->angleDeg,
              status->resolutionCdeg / 100.0, cfg->unit() == Unit::kMm ? "mm" : "cm");
  std::printf("status   %s\nmeasuring mode 0x%02X, availability 0x%02X\n", lms.lastStatus().describe().c_str(),
              cfg->measuringMode(), cfg->availability());
  return 0;
}

int runStream(const LmsOptions& o) {
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::atomic<long> received{0};
  ScanStream stream(toConfig(o), [&](const drivers::LaserScan& s) {
    const long n = ++received;
    if (o.count > 0 && n > o.count) return;
    if (o.json) {
      nlohmann::json j{{"seq", s.sequence}, {"stamp", s.stamp.toString()}, {"start_angle", s.startAngle},
                       {"angle_step", s.angleStep}, {"status", s.status}, {"ranges", s.ranges}};
      if (!s.remissions.empty()) j["remissions"] = s.remissions;
      std::printf("%s\n", j.dump().c_str());
    } else {
      float lo = 1e9f, hi = 0;
      for (float r : s.ranges)
        if (r > 0) lo = std::min(lo, r), hi = std::max(hi, r);
      std::printf("scan %llu  stamp %s  beams %zu  range %.3f..%.3f m  status 0x%02X\n",
                  static_cast<unsigned long long>(s.sequence), s.stamp.toString().c_str(), s.size(), lo, hi, s.status);
    }
    std::fflush(stdout);
  });
  std::ofstream record;
  if (!o.record.empty()) {
    record.open(o.record, std::ios::binary | std::ios::trunc);
    if (!record) throw std::runtime_error(o.record + ": cannot create");
    stream.setRawHook([&record](std::span<const std::uint8_t> bytes, Stamp) {
      record.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    });
  }
  stream.start();
  const auto t0 = std::chrono::steady_clock::now();
  while (!gInterrupted) {
    if (o.count > 0 && received >= o.count) break;
    if (o.duration > 0 && std::chrono::steady_clock::now() - t0 > std::chrono::duration<double>(o.duration)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const Result<void> stopped = stream.stop();
  const ScanStreamCounters c = stream.counters();
  const auto& l = c.device.link;
  std::fprintf(stderr,
               "lms: %llu scans, %llu lost, %llu bad; %llu telegrams, %llu CRC errors, %llu resyncs, %llu NAKs, "
               "%llu timeouts, %llu retries; %llu reconnects%s%s\n",
               (unsigned long long)c.device.scans, (unsigned long long)c.device.lostScans,
               (unsigned long long)c.device.badScans, (unsigned long long)l.reader.telegrams,
               (unsigned long long)l.reader.crcErrors, (unsigned long long)l.reader.resyncs, (unsigned long long)l.naks,
               (unsigned long long)l.timeouts, (unsigned long long)l.retries, (unsigned long long)c.reconnects,
               c.lastError.empty() ? "" : "; last error: ", c.lastError.c_str());
  if (record.is_open()) {
    record.close();
    if (!record) throw std::runtime_error(o.record + ": write error");
  }
  if (!stopped) throw std::runtime_error("stop: " + stopped.error().message());
  return received > 0 ? 0 : 1;
}

nlohmann::json describe(const StreamEvent& e) {
  const Telegram& t = e.telegram;
  nlohmann::json j{{"offset", e.offset}, {"addr", t.address}, {"cmd", t.command},
                   {"len", e.raw.size() - kFrameOverhead}, {"crc_ok", e.kind == StreamEvent::Kind::kTelegram}};
  j["status"] = t.status ? nlohmann::json(*t.status) : nlohmann::json(nullptr);
  if (e.kind != StreamEvent::Kind::kTelegram || !t.fromDevice()) return j;
  if (t.command == kMeasuredValues) {
    auto v = decodeMeasuredValues(t.data);
    if (!v) {
      j["error"] = v.error().message();
      return j;
    }
    j["unit"] = v->countWord.unit == Unit::kMm ? "mm" : "cm";
    j["partial"] = v->countWord.partial;
    j["partial_index"] = v->countWord.partialIndex;
    j["values"] = v->values;
    if (v->telegramIndex) j["telegram_index"] = *v->telegramIndex, j["scan_index"] = *v->scanIndex;
  } else if (t.command == kRangeRemission) {
    auto blocks = decodeRangeRemission(t.data);
    if (!blocks) {
      j["error"] = blocks.error().message();
      return j;
    }
    nlohmann::json values = nlohmann::json::array(), remissions = nlohmann::json::array();
    for (const auto& b : *blocks) {
      j["unit"] = b.countWord.unit == Unit::kMm ? "mm" : "cm";
      for (std::size_t i = 0; i < b.ranges.size(); ++i) values.push_back(b.ranges[i]), remissions.push_back(b.remissions[i]);
    }
    j["values"] = values;
    j["remissions"] = remissions;
  } else if (t.command == (static_cast<std::uint8_t>(drivers::lms291::Command::kType) | kReplyBit) || t.command == kPowerOnReply) {
    j["text"] = std::string(t.data.begin(), t.data.end());
  }
  return j;
}

int runDecode(const LmsOptions& o) {
  std::ifstream in(o.file, std::ios::binary);
  if (!in) throw std::runtime_error(o.file + ": cannot open");
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error(o.file + ": read error");
  TelegramReader reader(Direction::kAny);
  reader.feed(bytes, Stamp{});
  std::size_t found = 0;
  for (;;) {
    auto e = reader.next();
    if (!e) {
      if (!reader.expirePending()) break;  // end of file: what is left cannot complete
      continue;
    }
    if (e->kind != StreamEvent::Kind::kTelegram && e->kind != StreamEvent::Kind::kBadCrc) continue;
    std::printf("%s\n", describe(*e).dump().c_str());
    ++found;
  }
  const ReaderCounters& c = reader.counters();
  std::fprintf(stderr, "%s: %zu bytes, %llu telegrams, %llu CRC errors, %llu ACK, %llu NAK, %llu bytes skipped\n",
               o.file.c_str(), bytes.size(), (unsigned long long)c.telegrams, (unsigned long long)c.crcErrors,
               (unsigned long long)c.acks, (unsigned long long)c.naks, (unsigned long long)c.skippedBytes);
  if (found == 0) throw std::runtime_error(o.file + ": no LMS telegram found in " + std::to_string(bytes.size()) + " bytes");
  return 0;
}

void addDeviceOptions(CLI::App* sub, LmsOptions& o) {
  sub->add_option("DEVICE", o.device, "serial device (e.g. /dev/ttyUSB0) or the link of lms291-sim")->required();
  sub->add_option("--baud", o.baud, "speed to switch to: 9600 | 19200 | 38400 | 500000")->capture_default_str();
  sub->add_flag("--termios2", o.termios2, "set speeds with termios2/BOTHER even where cfsetspeed works");
  sub->add_option("--switch-pause-ms", o.pauseMs, "pause after a baud switch before verifying")->capture_default_str();
}

const bool registered = registerCommand(
    "lms", "Talk to a SICK LMS 291 laser scanner (probe, stream) or decode captured telegrams",
    [](CLI::App& app) {
      auto o = std::make_shared<LmsOptions>();
      app.require_subcommand(1);
      CLI::App* probe = app.add_subcommand("probe", "find the device's speed; print type, status, configuration (changes nothing but stops streaming)");
      addDeviceOptions(probe, *o);
      CLI::App* stream = app.add_subcommand("stream", "initialise the device and print scans until --count/--duration/Ctrl-C; then streaming off, back to 9600 baud");
      addDeviceOptions(stream, *o);
      stream->add_option("--angle", o->angle, "scan angle [deg]: 180 | 100")->capture_default_str();
      stream->add_option("--resolution", o->resolution, "angular resolution [deg]: 1 | 0.5 | 0.25 (0.25 only with --angle 100)")
          ->capture_default_str();
      stream->add_flag("--remission", o->remission, "range + remission telegrams (F5); needs --resolution 1");
      stream->add_flag("--interlaced", o->interlaced, "stream partial scans (mode 2A) and merge them in the driver");
      stream->add_flag("--rt-indices", o->realTimeIndices, "ask for real-time scan/telegram indices (counts lost scans)");
      stream->add_option("--count", o->count, "stop after N scans (0 = no limit)")->capture_default_str();
      stream->add_option("--duration", o->duration, "stop after S seconds (0 = no limit)")->capture_default_str();
      stream->add_flag("--json", o->json, "one JSON object per scan (seq, stamp, angles, status, ranges [m], remissions)");
      stream->add_option("--record", o->record, "write every byte read from the device to FILE (for `fusedet lms decode`)");
      CLI::App* decode = app.add_subcommand("decode", "print one JSON object per telegram in FILE (raw serial bytes)");
      decode->add_option("FILE", o->file, "a captured byte stream or a single telegram")->required();
      app.footer(
          "decode prints per telegram: offset, addr, cmd, len, crc_ok, status (null for host requests), and for\n"
          "measured values (B0) unit (mm|cm), partial, partial_index and values (integers as sent); for F5\n"
          "range+remission values and remissions. Counts go to stderr.\n"
          "Examples:\n"
          "  fusedet lms probe /dev/ttyUSB0\n"
          "  fusedet lms stream /dev/ttyUSB0 --baud 500000 --count 100\n"
          "  lms291-sim --link /tmp/lms & fusedet lms stream /tmp/lms --json --duration 2\n"
          "  fusedet lms stream /dev/ttyUSB0 --count 10 --record capture.bin && fusedet lms decode capture.bin\n"
          "  fusedet lms decode capture.bin | jq .values[180]\n"
          "Exit status: 0 on success; 1 on errors (printed as 'fusedet lms: error: ...') or when stream got no scan.\n"
          "stream prints its counters to stderr at the end (scans, lost, CRC errors, resyncs, NAKs, timeouts, reconnects).");
      return [o, probe, stream, decode]() -> int {
        if (probe->parsed()) return runProbe(*o);
        if (stream->parsed()) return runStream(*o);
        if (decode->parsed()) return runDecode(*o);
        return 2;
      };
    });

}  // namespace
}  // namespace fusedet::tools
